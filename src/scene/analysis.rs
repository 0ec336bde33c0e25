//! Per-pixel local analysis: which depths a pixel's light field holds, and
//! the shear that follows it ("model only what a scene needs").
//!
//! A pixel seeing one depth d has a light field sheared by
//! κ = (F − d)/d · 2A/s (see [`super::camera`]): its spectrum is a line and
//! the sample shear a = b = −κ aligns the sampler's empty region with it.
//! That holds to first order for any surface orientation: moving the lens
//! point by dL and the focal-plane point by dP moves the hit point by
//! Π((1 − λ)·dL + λ·dP), λ = d/F and Π the projection onto the surface
//! along the ray, a function of the combination x + κu alone; what a
//! slanted or curved surface adds is the change of κ across the footprint.
//! A pixel whose lens rays meet two or more depths (an occlusion edge) holds
//! two sheared lines, the seed's double wedge, which no single shear
//! aligns; a pixel whose rays all miss sees the constant background.

use super::Scene;
use crate::optimize::shear::shear_set;
use crate::points::PointSet;
use crate::rng::PREV_ONE;

/// What the probes of one pixel found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PixelKind {
    /// Every probe missed: a constant integrand.
    Background,
    /// One depth (within [`DEPTH_TOLERANCE`]): one sheared line.
    Single,
    /// Two or more depths, or hits and misses: a double wedge.
    Edge,
}

impl PixelKind {
    /// Lower-case name for tables.
    pub fn name(self) -> &'static str {
        match self {
            PixelKind::Background => "background",
            PixelKind::Single => "single",
            PixelKind::Edge => "edge",
        }
    }
}

/// Relative depth difference above which two probes see different depths.
pub const DEPTH_TOLERANCE: f64 = 0.05;

/// Probe positions along each lens axis (3 × 3 rays per pixel).
const PROBES: [f64; 3] = [0.1, 0.5, 0.9];

/// Positions along each axis of the footprint probes: 2 × 2 points of the
/// pixel, each through 4 × 4 points of the lens.
const FOOTPRINT_PIXEL: [f64; 2] = [0.1, 0.9];
const FOOTPRINT_LENS: [f64; 4] = [0.1, 0.37, 0.63, 0.9];

/// The pixel search compares warps across the footprint's range of κ when
/// that range moves the warp's argument t = x + κu by at least this
/// fraction of one of its strata (width (1 + |κ|)/√N for N samples).
pub const SLOPE_SPREAD_STRATA: f64 = 0.1;

/// Warp slopes the pixel search measures across the footprint's range.
pub const SLOPE_CANDIDATES: usize = 9;

/// Slopes below this (pixels per unit of u) follow no shear: the light
/// field moves by less across the whole lens, and the warp's lens
/// coordinate u = (t − x)/κ would carry the rounding of t (≈ ε) magnified
/// by 1/κ (2e-7 here, 0.02 at κ = 1e-14), so the points would no longer be
/// uniform.
pub const MIN_WARP_SLOPE: f64 = 1e-9;

/// The local analysis of one pixel.
#[derive(Debug, Clone, PartialEq)]
pub struct PixelAnalysis {
    /// What the probes found.
    pub kind: PixelKind,
    /// Depth seen by the centre ray (NaN on a miss).
    pub depth: f64,
    /// Its light-field shear κ (pixels per unit of u; 0 on a miss or for a
    /// pinhole).
    pub kappa: f64,
    /// The distinct shears κ of the depths the probes met, nearest first.
    pub kappas: Vec<f64>,
}

impl PixelAnalysis {
    /// The analytic sample shear: [`SampleShear::following`] the centre
    /// depth's κ (0, so no shear, for the background, a pinhole, and the
    /// soft-shadow integrand, whose (u, v) are on the light, not the lens).
    /// On an occlusion edge no single slope is right
    /// for every scene (measured: the occluder's slope lowers the dof
    /// scene's sphere-edge pixels by 8% at 64 spp, but a constant occluder
    /// over a striped wall is 1.9× above the wall's slope); the pilot
    /// policy measures those pixels.
    pub fn shear(&self) -> SampleShear {
        SampleShear::following(self.kappa)
    }
}

/// A transformation of a 4D set (x, y, u, v) that keeps every point uniform
/// in [0, 1)^4 (so estimates stay unbiased) and aligns it with a light
/// field g(x + κu, y + κv), in one of two forms.
///
/// `Position` is the torus shear of the seed and the shear search
/// (Singh & Jarosz 2017): x′ = x + a·u mod 1 with a = −κ makes x′ + κu
/// equal x up to a whole number. On the torus that whole number does not
/// matter; on a pixel's footprint it does, because g is not periodic: the
/// argument t = x + κu spans 1 + |κ| pixels and the wrapped points land at
/// random whole offsets (measured: no gain on defocused pixels).
///
/// `Warp` is the same alignment made exact on the footprint: a
/// measure-preserving map of each (position, lens) pair that draws the
/// argument t = x + κu from its own distribution (the trapezoid, the sum of
/// U[0, 1) and U[0, κ)) by inverting its CDF at the set's lens coordinate,
/// and the position given t uniformly on its allowed interval from the
/// set's position coordinate. The pixel integral becomes ∫ g(t) w(t) dt
/// sampled by the lens pattern's stratification (2D multi-jitter for umj),
/// for any κ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SampleShear {
    /// x′ = x + a·u, y′ = y + b·v (mod 1).
    Position([f64; 2]),
    /// The footprint warp of a light field with shear κ on both axes.
    Warp(f64),
}

impl SampleShear {
    /// No shear.
    pub const NONE: SampleShear = SampleShear::Position([0.0, 0.0]);

    /// The transformation that follows a light field of shear κ: the warp;
    /// none for an unsheared field (|κ| below [`MIN_WARP_SLOPE`]), where
    /// the warp's limit would exchange the position and lens coordinates
    /// and its lens coordinate loses its precision ([`footprint_warp`]).
    pub fn following(kappa: f64) -> SampleShear {
        if kappa.abs() < MIN_WARP_SLOPE {
            SampleShear::NONE
        } else {
            SampleShear::Warp(kappa)
        }
    }

    /// `position` or `warp`.
    pub fn form(&self) -> &'static str {
        match self {
            SampleShear::Position(_) => "position",
            SampleShear::Warp(_) => "warp",
        }
    }

    /// The two numbers: (a, b) of a position shear, (κ, κ) of a warp.
    pub fn amounts(&self) -> [f64; 2] {
        match *self {
            SampleShear::Position(s) => s,
            SampleShear::Warp(k) => [k, k],
        }
    }

    /// The light-field slope κ it follows (−a of a position shear).
    pub fn slope(&self) -> f64 {
        match *self {
            SampleShear::Position([a, _]) => -a,
            SampleShear::Warp(k) => k,
        }
    }

    /// The transformed set.
    ///
    /// # Panics
    /// On a set that is not 4D (callers check the sampler).
    pub fn apply(&self, set: PointSet) -> PointSet {
        let coords = match *self {
            SampleShear::Position([a, b]) if a == 0.0 && b == 0.0 => return set,
            SampleShear::Position(s) => {
                return shear_set(&set, s).expect("callers check the sampler is 4D");
            }
            SampleShear::Warp(kappa) => set
                .points()
                .flat_map(|p| {
                    let (x, u) = footprint_warp(kappa, p[2], p[0]);
                    let (y, v) = footprint_warp(kappa, p[3], p[1]);
                    [x, y, u, v]
                })
                .collect(),
        };
        PointSet::new(4, coords).expect("transformed coordinates lie in [0, 1)")
    }
}

/// (x, u) uniform on [0, 1)² from (ξ₁, ξ₂) uniform on [0, 1)², with
/// t = x + κu = T⁻¹(ξ₁) for T the CDF of t, and x = ξ₂ along the interval
/// of positions that t allows. A bijection that preserves measure, so
/// stratification of ξ₁ becomes stratification of the light field's
/// argument.
pub fn footprint_warp(kappa: f64, xi1: f64, xi2: f64) -> (f64, f64) {
    let k = kappa.abs();
    let clamp = |v: f64| v.clamp(0.0, PREV_ONE);
    if k == 0.0 {
        return (xi1, xi2);
    }
    // t = x + k·w with x ~ U[0, 1), w ~ U[0, 1): trapezoid on [0, 1 + k]
    // with ramps of width a = min(1, k), plateau height 1/b, b = max(1, k).
    let (a, b) = (k.min(1.0), k.max(1.0));
    let ramp = a / (2.0 * b);
    let t = if xi1 < ramp {
        (2.0 * a * b * xi1).sqrt()
    } else if xi1 < 1.0 - ramp {
        b * xi1 + 0.5 * a
    } else {
        a + b - (2.0 * a * b * (1.0 - xi1)).sqrt()
    };
    let (lo, hi) = ((t - k).max(0.0), t.min(1.0));
    let x = clamp(lo + xi2 * (hi - lo));
    let w = clamp((t - x) / k);
    // κ < 0: t − k = x − k·u with u = 1 − w.
    let u = if kappa > 0.0 { w } else { clamp(1.0 - w) };
    (x, u)
}

/// How the light field's slope changes across a single-depth pixel's
/// footprint: what a slanted or curved surface adds to the first-order
/// model (module docs).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct FootprintSlopes {
    /// The least and greatest κ of the centre ray's surface over 2 × 2
    /// pixel points × 4 × 4 lens points (probes within [`DEPTH_TOLERANCE`]
    /// of the centre depth), the centre's κ included.
    pub range: [f64; 2],
    /// That range in strata of the warp's argument t = x + κu at the
    /// sampler's N: (κ_max − κ_min)·√N/(1 + |κ|).
    pub spread: f64,
}

impl FootprintSlopes {
    /// Probes the footprint of pixel (px, py), analysed as `a`, for `n`
    /// samples per pixel; [κ, κ] and spread 0 unless the pixel sees one
    /// depth through a lens.
    pub fn probe(scene: &Scene, px: usize, py: usize, a: &PixelAnalysis, n: usize) -> Self {
        let mut range = [a.kappa, a.kappa];
        if scene.why_no_slope().is_none() && a.kind == PixelKind::Single {
            let d0 = a.depth;
            for x in FOOTPRINT_PIXEL {
                for y in FOOTPRINT_PIXEL {
                    for u in FOOTPRINT_LENS {
                        for v in FOOTPRINT_LENS {
                            let depth = depth_at(scene, px, py, [x, y, u, v]);
                            if let Some(d) =
                                depth.filter(|d| (d - d0).abs() <= DEPTH_TOLERANCE * d0)
                            {
                                let k = scene.camera().shear_at_depth(d);
                                range = [range[0].min(k), range[1].max(k)];
                            }
                        }
                    }
                }
            }
        }
        FootprintSlopes {
            range,
            spread: (range[1] - range[0]) * (n as f64).sqrt() / (1.0 + a.kappa.abs()),
        }
    }

    /// The warp slopes worth measuring besides the centre's:
    /// [`SLOPE_CANDIDATES`] evenly over the range when its spread reaches
    /// [`SLOPE_SPREAD_STRATA`] (the pixel's best slope may then differ from
    /// the centre's by what the sampler resolves), otherwise none; never
    /// one below [`MIN_WARP_SLOPE`] (a range across the focal plane), which
    /// no shear, always a candidate, stands for.
    pub fn candidates(&self) -> Vec<f64> {
        if self.spread < SLOPE_SPREAD_STRATA {
            return Vec::new();
        }
        let [lo, hi] = self.range;
        let last = (SLOPE_CANDIDATES - 1) as f64;
        (0..SLOPE_CANDIDATES)
            .map(|i| lo + (hi - lo) * i as f64 / last)
            .filter(|k| k.abs() >= MIN_WARP_SLOPE)
            .collect()
    }
}

/// The depth of the closest hit of pixel (px, py)'s ray at sample
/// (x, y, u, v), if any.
fn depth_at(scene: &Scene, px: usize, py: usize, sample: [f64; 4]) -> Option<f64> {
    let camera = scene.camera();
    let ray = camera.ray(px, py, sample);
    scene
        .geometry()
        .closest(ray.origin, ray.direction, 0.0)
        .map(|hit| camera.depth(hit.point))
}

/// Probes pixel (px, py) with 3 × 3 rays through its centre from points
/// spread over the lens (one ray for a pinhole or the soft-shadow
/// integrand).
pub fn analyse_pixel(scene: &Scene, px: usize, py: usize) -> PixelAnalysis {
    let camera = scene.camera();
    let lens = scene.why_no_slope().is_none();
    let probes: Vec<[f64; 2]> = if lens {
        PROBES
            .iter()
            .flat_map(|&u| PROBES.iter().map(move |&v| [u, v]))
            .collect()
    } else {
        vec![[0.5, 0.5]]
    };
    let depth_of = |[u, v]: [f64; 2]| depth_at(scene, px, py, [0.5, 0.5, u, v]);
    let centre = depth_of([0.5, 0.5]);
    let mut depths: Vec<Option<f64>> = probes.iter().map(|&p| depth_of(p)).collect();
    depths.sort_by(|a, b| match (a, b) {
        (Some(x), Some(y)) => x.total_cmp(y),
        (Some(_), None) => std::cmp::Ordering::Less,
        (None, Some(_)) => std::cmp::Ordering::Greater,
        (None, None) => std::cmp::Ordering::Equal,
    });
    // Cluster sorted depths: a gap above the tolerance starts a new depth.
    let mut clusters: Vec<f64> = Vec::new();
    let mut missed = false;
    for d in &depths {
        match d {
            Some(d) => match clusters.last() {
                Some(&last) if (d - last) <= DEPTH_TOLERANCE * last => {}
                _ => clusters.push(*d),
            },
            None => missed = true,
        }
    }
    let kind = match (clusters.len(), missed) {
        (0, _) => PixelKind::Background,
        (1, false) => PixelKind::Single,
        _ => PixelKind::Edge,
    };
    let kappa_of = |d: f64| {
        if lens { camera.shear_at_depth(d) } else { 0.0 }
    };
    PixelAnalysis {
        kind,
        depth: centre.unwrap_or(f64::NAN),
        kappa: centre.map_or(0.0, kappa_of),
        kappas: clusters.into_iter().map(kappa_of).collect(),
    }
}
