//! Triangle meshes in an obvhs BVH, binary (BVH2; the default: 1.26× the
//! camera rays per second of the CWBVH on this 2-core machine,
//! results/scene/bench-render.csv) or compressed-wide (CWBVH; Ylitie et al.
//! 2017): closest hits for camera rays, any hit for shadow rays. Traversal
//! is f32 (obvhs) about the camera: triangles and ray origins are stored
//! relative to a world point (the camera's position) taken away in f64, so
//! a scene placed at 1e8 renders as at the origin (in world coordinates f32
//! spacing there is 8, and a sphere of radius 0.3 vanished); hit points are
//! rebuilt in f64 world coordinates from the ray parameter.

use std::time::Duration;

use glam::Vec3A;
use obvhs::BvhBuildParams;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::builder::build_bvh2_from_tris;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;

use super::description::{ObjectFile, ShapeKind};

/// A triangle's three vertices in model space.
pub type ModelTriangle = [[f64; 3]; 3];

/// A rigid placement: scale, then rotation about y, then translation.
#[derive(Debug, Clone, Copy)]
pub struct Placement {
    scale: [f64; 3],
    cos: f64,
    sin: f64,
    translate: [f64; 3],
}

impl Placement {
    /// From an object's fields.
    pub fn of(object: &ObjectFile) -> Placement {
        let angle = object.rotate_y_degrees.to_radians();
        Placement {
            scale: object.scale,
            cos: angle.cos(),
            sin: angle.sin(),
            translate: object.translate,
        }
    }

    /// A model-space point in the world.
    pub fn apply(&self, p: [f64; 3]) -> [f64; 3] {
        let s = [
            p[0] * self.scale[0],
            p[1] * self.scale[1],
            p[2] * self.scale[2],
        ];
        [
            self.cos * s[0] + self.sin * s[2] + self.translate[0],
            s[1] + self.translate[1],
            -self.sin * s[0] + self.cos * s[2] + self.translate[2],
        ]
    }

    /// A world point in the object's frame (translation and rotation undone,
    /// scale kept): where solid textures are evaluated.
    pub fn frame(&self, p: [f64; 3]) -> [f64; 3] {
        let q = [
            p[0] - self.translate[0],
            p[1] - self.translate[1],
            p[2] - self.translate[2],
        ];
        [
            self.cos * q[0] - self.sin * q[2],
            q[1],
            self.sin * q[0] + self.cos * q[2],
        ]
    }
}

/// The model-space triangles of a built-in shape; `None` for an `obj`
/// shape, whose triangles come from its file (`super::mesh`).
pub fn shape_triangles(shape: ShapeKind, subdivisions: u32) -> Option<Vec<ModelTriangle>> {
    Some(match shape {
        ShapeKind::Obj => return None,
        ShapeKind::Quad => vec![
            [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0]],
            [[-1.0, -1.0, 0.0], [1.0, 1.0, 0.0], [-1.0, 1.0, 0.0]],
        ],
        ShapeKind::Box => {
            let mut out = Vec::with_capacity(12);
            // Each face: axis a, sign s, the other two axes b, c.
            for a in 0..3 {
                for s in [-1.0, 1.0] {
                    let (b, c) = ((a + 1) % 3, (a + 2) % 3);
                    let corner = |u: f64, v: f64| {
                        let mut p = [0.0; 3];
                        p[a] = s;
                        p[b] = u;
                        p[c] = v;
                        p
                    };
                    out.push([corner(-1.0, -1.0), corner(1.0, -1.0), corner(1.0, 1.0)]);
                    out.push([corner(-1.0, -1.0), corner(1.0, 1.0), corner(-1.0, 1.0)]);
                }
            }
            out
        }
        ShapeKind::Sphere => icosphere(subdivisions),
    })
}

/// A unit icosahedron subdivided `levels` times, vertices on the sphere
/// (20·4^levels triangles).
fn icosphere(levels: u32) -> Vec<[[f64; 3]; 3]> {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let v = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    const FACES: [[usize; 3]; 20] = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let unit = |p: [f64; 3]| {
        let n = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        [p[0] / n, p[1] / n, p[2] / n]
    };
    let mut tris: Vec<[[f64; 3]; 3]> = FACES
        .iter()
        .map(|f| [unit(v[f[0]]), unit(v[f[1]]), unit(v[f[2]])])
        .collect();
    for _ in 0..levels {
        let mid = |a: [f64; 3], b: [f64; 3]| unit([a[0] + b[0], a[1] + b[1], a[2] + b[2]]);
        tris = tris
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
                [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
            })
            .collect();
    }
    tris
}

/// The closest surface a ray meets.
#[derive(Debug, Clone, Copy)]
pub struct Hit {
    /// Ray parameter (distance for a unit direction).
    pub t: f64,
    /// The point, in the world.
    pub point: [f64; 3],
    /// The geometric normal, unit length, facing the ray's origin.
    pub normal: [f64; 3],
    /// Index of the object in the scene file.
    pub object: usize,
}

/// Which obvhs tree holds the triangles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BvhKind {
    /// Compressed wide BVH (8-wide nodes).
    Cwbvh,
    /// Binary BVH.
    Bvh2,
}

enum Tree {
    Wide(CwBvh),
    Binary(Bvh2),
}

/// Every triangle of a scene in one BVH, in f32 coordinates relative to
/// a world point (`origin`).
pub struct Geometry {
    tree: Tree,
    triangles: Vec<Triangle>,
    object_of: Vec<u32>,
    origin: [f64; 3],
}

impl Geometry {
    /// Builds a BVH of the given kind over the objects' triangles:
    /// `meshes[i]` holds object i's in model space; `origin` is the world
    /// point the f32 coordinates are relative to (the camera's position:
    /// precision is kept where the picture is).
    pub fn build_with(
        objects: &[ObjectFile],
        meshes: &[Vec<ModelTriangle>],
        kind: BvhKind,
        origin: [f64; 3],
    ) -> Geometry {
        let mut triangles = Vec::new();
        let mut object_of = Vec::new();
        for (i, (o, mesh)) in objects.iter().zip(meshes).enumerate() {
            let place = Placement::of(o);
            for &[a, b, c] in mesh {
                let v = |p| relative(place.apply(p), origin);
                triangles.push(Triangle {
                    v0: v(a),
                    v1: v(b),
                    v2: v(c),
                });
                object_of.push(i as u32);
            }
        }
        let params = BvhBuildParams::medium_build();
        let tree = match kind {
            BvhKind::Cwbvh => Tree::Wide(build_cwbvh_from_tris(
                &triangles,
                params,
                &mut Duration::default(),
            )),
            BvhKind::Bvh2 => Tree::Binary(build_bvh2_from_tris(
                &triangles,
                params,
                &mut Duration::default(),
            )),
        };
        Geometry {
            tree,
            triangles,
            object_of,
            origin,
        }
    }

    /// The triangle a tree's primitive slot refers to.
    fn primitive(&self, slot: usize) -> usize {
        let indices = match &self.tree {
            Tree::Wide(b) => &b.primitive_indices,
            Tree::Binary(b) => &b.primitive_indices,
        };
        indices[slot] as usize
    }

    /// The largest coordinate of world point `p` as the f32 traversal sees
    /// it (relative to the origin), which sets its rounding.
    pub fn magnitude(&self, p: [f64; 3]) -> f64 {
        (0..3).fold(0.0, |m: f64, k| m.max((p[k] - self.origin[k]).abs()))
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The closest hit along `origin + t·direction`, t in (t_min, ∞).
    pub fn closest(&self, origin: [f64; 3], direction: [f64; 3], t_min: f64) -> Option<Hit> {
        let ray = Ray::new(
            relative(origin, self.origin),
            f32v(direction),
            t_min as f32,
            f32::INFINITY,
        );
        let mut hit = RayHit::none();
        let intersect =
            |ray: &Ray, slot: usize| self.triangles[self.primitive(slot)].intersect(ray);
        let found = match &self.tree {
            Tree::Wide(b) => b.ray_traverse(ray, &mut hit, intersect),
            Tree::Binary(b) => b.ray_traverse(ray, &mut hit, intersect),
        };
        if !found {
            return None;
        }
        let index = self.primitive(hit.primitive_id as usize);
        let tri = &self.triangles[index];
        let n = (tri.v1 - tri.v0).cross(tri.v2 - tri.v0).normalize();
        let mut normal = [f64::from(n.x), f64::from(n.y), f64::from(n.z)];
        if dot(normal, direction) > 0.0 {
            normal = normal.map(|c| -c);
        }
        let t = f64::from(hit.t);
        Some(Hit {
            t,
            point: [
                origin[0] + t * direction[0],
                origin[1] + t * direction[1],
                origin[2] + t * direction[2],
            ],
            normal,
            object: self.object_of[index] as usize,
        })
    }

    /// Whether the segment from `origin` to `origin + length·direction`
    /// meets no triangle (any-hit traversal). The caller keeps the segment
    /// off the surfaces at its ends: an origin offset along the normal, a
    /// length stopping short of the light.
    pub fn unoccluded(&self, origin: [f64; 3], direction: [f64; 3], length: f64) -> bool {
        let ray = Ray::new(
            relative(origin, self.origin),
            f32v(direction),
            0.0,
            length as f32,
        );
        let intersect =
            |ray: &Ray, slot: usize| self.triangles[self.primitive(slot)].intersect(ray);
        match &self.tree {
            Tree::Wide(b) => b.ray_traverse_miss(ray, intersect),
            Tree::Binary(b) => b.ray_traverse_miss(ray, intersect),
        }
    }
}

fn f32v(p: [f64; 3]) -> Vec3A {
    Vec3A::new(p[0] as f32, p[1] as f32, p[2] as f32)
}

/// `p − origin` in f64, then rounded to f32.
fn relative(p: [f64; 3], origin: [f64; 3]) -> Vec3A {
    f32v(std::array::from_fn(|k| p[k] - origin[k]))
}

pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
