//! Parsing `name:key=value,...` integrand specs, and the registry that
//! `varspec integrands --list` prints.

use super::{
    Cosine, Defocus, DefocusShape, Disk, Gaussian, HalfPlane, Integrand, IntegrandError, Layers,
    Rect,
};

/// A registered integrand.
pub struct IntegrandInfo {
    /// Name.
    pub name: &'static str,
    /// Dimension.
    pub dim: usize,
    /// What it is.
    pub summary: &'static str,
    /// (key, default, meaning).
    pub params: &'static [(&'static str, &'static str, &'static str)],
}

/// The least |c2 − c1| of `layers`: closer layers are one defocus.
const LAYERS_MIN_SEPARATION: f64 = 0.05;

/// Every integrand.
pub const INTEGRANDS: &[IntegrandInfo] = &[
    IntegrandInfo {
        name: "cos",
        dim: 2,
        summary: "f = 1 + cos(2π k·x): a finite spectrum (P_f = 1/4 at ±k)",
        params: &[
            ("kx", "1", "integer frequency, x"),
            ("ky", "0", "integer frequency, y"),
        ],
    },
    IntegrandInfo {
        name: "disk",
        dim: 2,
        summary: "indicator of a disk (periodic images): F = r J1(2πr|k|)/|k| e^(−2πik·c)",
        params: &[
            ("r", "0.3", "radius in (0, 0.5]"),
            ("cx", "0.5", "centre x, in [-1, 2] (wraps on the torus)"),
            ("cy", "0.5", "centre y, in [-1, 2]"),
        ],
    },
    IntegrandInfo {
        name: "box",
        dim: 2,
        summary: "indicator of a rotated rectangle: product of sincs; c_f a product of triangles",
        params: &[
            (
                "w",
                "0.5",
                "side along the first axis (cos θ, sin θ), in (0, 1]",
            ),
            ("h", "0.25", "side along the second axis, in (0, 1]"),
            ("cx", "0.5", "centre x, in [-1, 2] (wraps on the torus)"),
            ("cy", "0.5", "centre y, in [-1, 2]"),
            (
                "angle",
                "0",
                "θ in degrees, counter-clockwise, in [-360, 360]",
            ),
        ],
    },
    IntegrandInfo {
        name: "gaussian",
        dim: 2,
        summary: "sum of the periodic images of a Gaussian of peak 1",
        params: &[
            (
                "sx",
                "0.1",
                "standard deviation along the first axis, in (0, 0.5]",
            ),
            (
                "sy",
                "sx",
                "standard deviation along the second axis, in (0, 0.5]",
            ),
            (
                "angle",
                "0",
                "θ in degrees, counter-clockwise, in [-360, 360]",
            ),
            ("cx", "0.5", "centre x, in [-1, 2] (wraps on the torus)"),
            ("cy", "0.5", "centre y, in [-1, 2]"),
        ],
    },
    IntegrandInfo {
        name: "halfplane",
        dim: 2,
        summary: "indicator of {x in the unit square: (x − p)·n ≥ 0}, n = (cos θ, sin θ), p = (½,½) + offset·n",
        params: &[
            ("angle", "0", "θ in degrees, in [-360, 360]"),
            (
                "offset",
                "0",
                "signed distance of the edge from the centre, in [-1, 1]",
            ),
        ],
    },
    IntegrandInfo {
        name: "defocus",
        dim: 4,
        summary: "thin-lens light field f(x,y,u,v) = g(x + c(u−½), y + c(v−½)); energy on a sheared plane",
        params: &[
            (
                "shape",
                "box",
                "g: box (side size), disk (diameter size) or gaussian (4σ = size), centred at (½,½)",
            ),
            ("size", "0.3", "see shape, in [1e-4, 1]"),
            ("c", "0", "shear c = (F − d)/d, in [-16, 16]"),
        ],
    },
    IntegrandInfo {
        name: "layers",
        dim: 4,
        summary: "two defocus layers (1 − mix)·g sheared by c1 + mix·g sheared by c2: a double wedge",
        params: &[
            ("shape", "box", "g: box, disk or gaussian, as for defocus"),
            ("size", "0.3", "see defocus, in [1e-4, 1]"),
            ("c1", "0.5", "shear of the first layer, in [-16, 16]"),
            (
                "c2",
                "-0.2",
                "shear of the second layer, in [-16, 16], |c2 − c1| ≥ 0.05",
            ),
            ("mix", "0.5", "weight of the second layer, in [0, 1]"),
        ],
    },
];

/// Key-value parameters of one spec, checked against the registry.
struct Params {
    info: &'static IntegrandInfo,
    pairs: Vec<(String, String)>,
}

impl Params {
    fn text(&self, key: &'static str) -> &str {
        self.pairs
            .iter()
            .rev()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
            .or_else(|| self.info.params.iter().find(|p| p.0 == key).map(|p| p.1))
            .expect("registered key")
    }

    fn given(&self, key: &str) -> bool {
        self.pairs.iter().any(|(k, _)| k == key)
    }

    fn bad(&self, key: &'static str, expected: &str) -> IntegrandError {
        IntegrandError::Value {
            integrand: self.info.name,
            key,
            value: self.text(key).to_string(),
            expected: expected.to_string(),
        }
    }

    /// A finite number satisfying `ok`, else an error quoting `expected`
    /// (and saying so when the text is not a number at all).
    fn number(
        &self,
        key: &'static str,
        ok: impl Fn(f64) -> bool,
        expected: &str,
    ) -> Result<f64, IntegrandError> {
        let Ok(v) = self.text(key).parse::<f64>() else {
            return Err(self.bad(key, &format!("a number ({expected})")));
        };
        Some(v)
            .filter(|v| v.is_finite() && ok(*v))
            .ok_or_else(|| self.bad(key, expected))
    }

    fn integer(&self, key: &'static str) -> Result<i64, IntegrandError> {
        self.text(key)
            .parse::<i64>()
            .ok()
            .filter(|v| v.unsigned_abs() <= 1 << 40)
            .ok_or_else(|| {
                self.bad(
                    key,
                    "an integer in [-2^40, 2^40] (whole periods keep the integrand periodic; \
                     the bound keeps its phase exact), written without a decimal point or exponent",
                )
            })
    }

    fn shape(&self) -> Result<DefocusShape, IntegrandError> {
        match self.text("shape") {
            "box" => Ok(DefocusShape::Box),
            "disk" => Ok(DefocusShape::Disk),
            "gaussian" => Ok(DefocusShape::Gaussian),
            _ => Err(self.bad("shape", "box, disk or gaussian")),
        }
    }

    /// A centre on the torus: it wraps, so [−1, 2] says every place (far
    /// out a coordinate loses the fraction that places it).
    fn centre(&self) -> Result<[f64; 2], IntegrandError> {
        let on_torus = |c: f64| (-1.0..=2.0).contains(&c);
        let what = "a coordinate in [-1, 2] (it wraps on the torus)";
        Ok([
            self.number("cx", on_torus, what)?,
            self.number("cy", on_torus, what)?,
        ])
    }

    /// An angle in degrees, one turn either way (far out an angle loses the
    /// fraction of a turn that orients it).
    fn angle(&self) -> Result<f64, IntegrandError> {
        self.number(
            "angle",
            |a| (-360.0..=360.0).contains(&a),
            "an angle in degrees in [-360, 360]",
        )
    }
}

/// The name of a scene-pixel spec (`scene:NAME,px=X,py=Y`, parsed by
/// `scene::pixel`, not here).
const SCENE_PIXEL: &str = "scene";

/// What follows `scene:` in a scene-pixel spec (whitespace around `scene`
/// ignored, as around every name); `None` for any other spec.
pub fn scene_pixel_rest(spec: &str) -> Option<&str> {
    spec.split_once(':')
        .and_then(|(head, rest)| (head.trim() == SCENE_PIXEL).then_some(rest))
}

/// Parses `name:key=value,...` (or just `name`) into an integrand.
///
/// # Errors
/// [`IntegrandError`] for an unknown name or key, malformed text, or a value
/// outside its domain (r > 0.5, negative sizes, NaN, …).
pub fn parse(spec: &str) -> Result<Box<dyn Integrand>, IntegrandError> {
    let (name, rest) = spec.split_once(':').unwrap_or((spec, ""));
    let name = name.trim();
    let known = || {
        INTEGRANDS
            .iter()
            .map(|i| i.name)
            .collect::<Vec<_>>()
            .join(", ")
    };
    if name == SCENE_PIXEL {
        return Err(IntegrandError::ScenePixel { known: known() });
    }
    let info =
        INTEGRANDS
            .iter()
            .find(|i| i.name == name)
            .ok_or_else(|| IntegrandError::Unknown {
                name: name.to_string(),
                suggestion: crate::suggest::did_you_mean(name, INTEGRANDS.iter().map(|i| i.name)),
                known: known(),
            })?;
    let mut pairs = Vec::new();
    let list = crate::spec_params::key_values(rest).map_err(|reason| IntegrandError::Syntax {
        spec: spec.to_string(),
        reason,
    })?;
    for (k, v) in list {
        if !info.params.iter().any(|p| p.0 == k) {
            return Err(IntegrandError::UnknownKey {
                integrand: info.name,
                key: k.to_string(),
                suggestion: crate::suggest::did_you_mean(k, info.params.iter().map(|p| p.0)),
                known: info
                    .params
                    .iter()
                    .map(|p| p.0)
                    .collect::<Vec<_>>()
                    .join(", "),
            });
        }
        if pairs.iter().any(|(seen, _): &(String, String)| seen == k) {
            return Err(IntegrandError::Repeated {
                spec: spec.to_string(),
                key: k.to_string(),
            });
        }
        pairs.push((k.to_string(), v.to_string()));
    }
    let p = Params { info, pairs };
    let unit = |v: f64| v > 0.0 && v <= 1.0;
    let size = |v: f64| (super::defocus::MIN_SIZE..=1.0).contains(&v);
    Ok(match info.name {
        "cos" => Box::new(Cosine::new([p.integer("kx")?, p.integer("ky")?])?),
        "disk" => Box::new(Disk::new(
            p.number("r", |r| r > 0.0 && r <= 0.5, "a radius in (0, 0.5]")?,
            p.centre()?,
        )?),
        "box" => {
            let (w, h) = (
                p.number("w", unit, "a side in (0, 1]")?,
                p.number("h", unit, "a side in (0, 1]")?,
            );
            let angle = p.angle()?;
            Rect::new(w, h, p.centre()?, angle)
                .map_err(|e| p.bad("angle", &e))?
                .boxed()
        }
        "gaussian" => {
            let sx = p.number(
                "sx",
                |s| s > 0.0 && s <= 0.5,
                "a standard deviation in (0, 0.5]",
            )?;
            let sy = if p.given("sy") {
                p.number(
                    "sy",
                    |s| s > 0.0 && s <= 0.5,
                    "a standard deviation in (0, 0.5]",
                )?
            } else {
                sx
            };
            Box::new(Gaussian::new(sx, sy, p.angle()?, p.centre()?)?)
        }
        "halfplane" => Box::new(HalfPlane::new(
            p.angle()?,
            p.number("offset", |o| o.abs() <= 1.0, "an offset in [-1, 1]")?,
        )?),
        "defocus" => Box::new(Defocus::new(
            p.shape()?,
            p.number("size", size, "a size in [1e-4, 1]")?,
            p.number("c", |c| c.abs() <= 16.0, "a shear in [-16, 16]")?,
        )?),
        "layers" => {
            let shear = |key| p.number(key, |c: f64| c.abs() <= 16.0, "a shear in [-16, 16]");
            let (c1, c2) = (shear("c1")?, shear("c2")?);
            // 0.05 as written: c1 = 0.3, c2 = 0.25 differ by 0.0499…9 in
            // binary, and the spec's decimals are what the user compares.
            if (c2 - c1).abs() < LAYERS_MIN_SEPARATION * (1.0 - 1e-12) {
                return Err(p.bad("c2", "a shear at least 0.05 from c1 (else use defocus)"));
            }
            Box::new(Layers::new(
                p.shape()?,
                p.number("size", size, "a size in [1e-4, 1]")?,
                c1,
                c2,
                p.number("mix", |m| (0.0..=1.0).contains(&m), "a weight in [0, 1]")?,
            )?)
        }
        _ => unreachable!("every registered integrand is built above"),
    })
}
