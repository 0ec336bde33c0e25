//! The tour as one self-contained HTML page: the template
//! (`templates/tour.html`, minijinja) filled with the [`Tour`]'s data, every
//! picture embedded as a `data:` URI so the page opens anywhere on its own.

use std::path::Path;

use base64::Engine;
use serde_json::Value;

use super::{Tour, TourError};

/// The page and the sections it includes, by template name.
const TEMPLATES: [(&str, &str); 6] = [
    ("tour.html", include_str!("templates/tour.html")),
    ("predict.html", include_str!("templates/predict.html")),
    ("square.html", include_str!("templates/square.html")),
    ("shear.html", include_str!("templates/shear.html")),
    ("scene.html", include_str!("templates/scene.html")),
    ("speed.html", include_str!("templates/speed.html")),
];

fn fail<E: std::fmt::Display>(e: E) -> TourError {
    TourError::Step {
        step: "writing index.html",
        message: e.to_string(),
    }
}

/// Every `{file, caption}` object gains `data`: the picture at `folder/file`
/// as a base64 `data:` URI.
fn embed(value: &mut Value, folder: &Path) -> Result<(), TourError> {
    match value {
        Value::Object(map) => {
            if let (Some(Value::String(file)), true) =
                (map.get("file"), map.contains_key("caption"))
            {
                let bytes = crate::io::read_output(&folder.join(file.as_str())).map_err(fail)?;
                let data = base64::engine::general_purpose::STANDARD.encode(bytes);
                map.insert(
                    "data".into(),
                    Value::String(format!("data:image/png;base64,{data}")),
                );
            }
            for v in map.values_mut() {
                embed(v, folder)?;
            }
        }
        Value::Array(items) => {
            for v in items {
                embed(v, folder)?;
            }
        }
        _ => {}
    }
    Ok(())
}

/// Writes `folder/index.html` for `tour` (its pictures already in `folder`).
///
/// # Errors
/// [`TourError`] for a missing picture, a template error or the write.
pub fn render_tour(tour: &Tour, folder: &Path) -> Result<(), TourError> {
    let mut context = serde_json::to_value(tour).map_err(fail)?;
    embed(&mut context, folder)?;
    if let Value::Object(map) = &mut context {
        map.insert(
            "version".into(),
            Value::String(env!("CARGO_PKG_VERSION").into()),
        );
        map.insert("threads".into(), Value::from(rayon::current_num_threads()));
        map.insert("seed".into(), Value::from(tour.options.seed));
    }
    let html = page("tour.html", &context)?;
    crate::io::write_atomic(&folder.join("index.html"), |w| w.write_all(html.as_bytes()))
        .map_err(fail)
}

/// Template `name` (the page, `tour.html`, or one section) filled with
/// `context` (the tour's data, pictures embedded).
fn page(name: &str, context: &Value) -> Result<String, TourError> {
    let mut env = minijinja::Environment::new();
    // A number the tour could not measure is null in its data (serde_json
    // writes NaN so); printf formatting refuses null, so the page says n/a
    // there (a constant integrand's 0/0 failed the whole page after the work).
    env.add_filter(
        "format",
        |state: &minijinja::State,
         spec: &minijinja::Value,
         args: minijinja::value::Rest<minijinja::Value>| {
            // Only null: an undefined value is a template mistake and fails.
            if args.iter().any(minijinja::Value::is_none) {
                Ok(minijinja::Value::from_safe_string("n/a".into()))
            } else {
                minijinja::filters::format(state, spec, args)
            }
        },
    );
    for (template, text) in TEMPLATES {
        env.add_template(template, text).map_err(fail)?;
    }
    env.get_template(name)
        .and_then(|t| t.render(context))
        .map_err(fail)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shear section's data for a light field with `analytic` layer
    /// shears.
    fn shear_context(analytic: &[[f64; 2]]) -> Value {
        serde_json::json!({ "shear": {
            "integrand": "light-field", "n": 256, "shear": [-0.15, -0.15],
            "initial": [-0.12, -0.12], "initial_value": 8e-5, "analytic": analytic,
            "unsheared": 8e-5, "optimum": 7.7e-5, "truncation_bound": 0.001,
            "reduction": 1.04, "check_before": 8e-5, "check_before_low": 7e-5,
            "check_before_high": 9e-5, "check_after": 7.6e-5, "check_after_low": 7e-5,
            "check_after_high": 8e-5, "seconds": 1.0, "spectra": [], "commands": []
        }})
    }

    #[test]
    fn a_double_wedge_is_drawn_as_two_layers() {
        let two = page("shear.html", &shear_context(&[[-0.5, -0.5], [0.2, 0.2]])).unwrap();
        assert!(two.contains("2 sheared planes"), "{two}");
        assert!(two.contains("double wedge"));
        assert!(two.contains("analytic −c, layer 1</td><td>(-0.500, -0.500)"));
        assert!(two.contains("analytic −c, layer 2</td><td>(0.200, 0.200)"));
        let one = page("shear.html", &shear_context(&[[-0.45, -0.45]])).unwrap();
        assert!(one.contains("the sheared plane"), "{one}");
        assert!(!one.contains("double wedge") && !one.contains("layer 1"));
        assert!(one.contains("analytic −c</td><td>(-0.450, -0.450)"));
    }

    /// A number the tour could not measure is null in its data (a NaN):
    /// the page says n/a there instead of failing to render after the work.
    #[test]
    fn an_unmeasured_number_reads_n_a() {
        let mut context = shear_context(&[[-0.45, -0.45]]);
        context["shear"]["check_after_low"] = Value::Null;
        context["shear"]["truncation_bound"] = Value::Null;
        let text = page("shear.html", &context).unwrap();
        assert!(text.contains("7.600e-05 [n/a, 8.000e-05]"), "{text}");
        assert!(text.contains("truncation bound n/a)"), "{text}");
        // A misspelt field is a template mistake, not a missing number.
        context["shear"].as_object_mut().unwrap().remove("optimum");
        assert!(page("shear.html", &context).is_err());
    }
}
