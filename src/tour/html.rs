//! The tour as one self-contained HTML page: the template
//! (`templates/tour.html`, minijinja) filled with the [`Tour`]'s data, every
//! picture embedded as a `data:` URI so the page opens anywhere on its own.

use std::path::Path;

use base64::Engine;
use serde_json::Value;

use super::{Tour, TourError};

const TEMPLATE: &str = include_str!("templates/tour.html");

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
    let mut env = minijinja::Environment::new();
    env.add_template("tour.html", TEMPLATE).map_err(fail)?;
    let html = env
        .get_template("tour.html")
        .and_then(|t| t.render(&context))
        .map_err(fail)?;
    crate::io::write_atomic(&folder.join("index.html"), |w| w.write_all(html.as_bytes()))
        .map_err(fail)
}
