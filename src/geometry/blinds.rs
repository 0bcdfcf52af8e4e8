//! Venetian blinds as triangles: the `Blinds` shape of the scene description, laid out with the
//! conventions and numbers of Radiance's `genblinds`, so that
//! `genblinds mat name DEPTH WIDTH HEIGHT COUNT ANGLE [-r R]` moved by `xform` is its Radiance
//! twin, polygon for polygon.
//!
//! genblinds' frame, and how a `Blinds` maps it (lengths in metres):
//! * +Y runs along the slats (`width_dir`), from 0 to `width`;
//! * +Z runs up the stack (`up`): slat n = 1..=count hangs at z = height·(n − ½)/count;
//! * +X (`out`) is the normal of the blinds' plane: every slat pivots about its edge at x = 0
//!   (the plane through `origin`) and reaches toward +X by its depth. A positive angle lifts
//!   the +X edge: a flat slat runs from (0, 0) to depth·(cos angle, sin angle) in (x, z).
//!
//! A point (x, y, z) of genblinds is `origin + x·out + y·width_dir + z·up`. The three
//! directions need only be perpendicular: a left-handed triple (out × width_dir = −up) is
//! genblinds' output mirrored (`xform -mx`), the same slats seen in a mirror.
//!
//! A curved slat is an arc of a circle of radius |r| through the flat slat's two edges (its
//! chord, of length `depth`), spanning θ = 2·asin(depth / 2|r|) in ⌈θ / 3°⌉ equal segments
//! (genblinds' count, with its 0.99999 rounding). For r > 0 (genblinds' `-r r`) the centre of
//! curvature is on the +Z side of the chord, so the slat sags in the middle (concave up at
//! angle 0); r < 0 (genblinds' `+r |r|`) bulges up.

use super::TriangleMesh;
use crate::description::context::{Context, SceneError};
use crate::description::schema::ShapeDesc;
use glam::DVec3;

/// Most triangles one `Blinds` shape may expand to (count × segments per slat × 2): beyond it
/// the description is taken for a mistake (a spacing in millimetres, say), not built.
pub const MAX_BLINDS_TRIANGLES: u64 = 1_000_000;

/// Largest angle (degrees) one segment of a curved slat spans, as in genblinds (`DELTA`).
const SEGMENT_DEG: f64 = 3.0;

/// Cosine above which two directions given as perpendicular are taken as not (a 0.006° slack
/// for directions typed with a few decimals).
const PERPENDICULAR_COS: f64 = 1e-4;

/// Venetian blinds: `count` identical slats stacked along `up` (see the module's frame).
#[derive(Clone, Debug, PartialEq)]
pub struct Blinds {
    /// genblinds' (0, 0, 0): the bottom end of the slats' pivot line.
    pub origin: DVec3,
    /// Unit, along the slats (genblinds' +Y).
    pub width_dir: DVec3,
    /// Unit, up the stack (genblinds' +Z).
    pub up: DVec3,
    /// Unit, the way the slats reach from their pivots (genblinds' +X).
    pub out: DVec3,
    pub width_m: f64,
    pub height_m: f64,
    /// Slat depth: the chord from the pivot edge to the free edge.
    pub depth_m: f64,
    pub count: u32,
    /// Tilt of the chord above the plane normal to `up`; positive lifts the free (`out`) edge.
    pub angle_deg: f64,
    /// Signed radius of curvature (genblinds' `-r`); `None` for flat slats.
    pub curvature_radius_m: Option<f64>,
}

/// Number of flat segments of a slat: 1 when flat, else genblinds' ⌈θ / 3°⌉.
pub fn segments_per_slat(depth_m: f64, curvature_radius_m: Option<f64>) -> usize {
    match curvature_radius_m {
        None => 1,
        Some(r) => {
            let theta = 2.0 * (depth_m / (2.0 * r.abs())).asin();
            // genblinds' rounding, kept so that the counts agree at whole multiples of 3°.
            ((theta / SEGMENT_DEG.to_radians() + 0.99999) as usize).max(1)
        }
    }
}

impl Blinds {
    /// The slat's cross-section from its pivot edge (0, 0) to its free edge, as (x, z) in
    /// genblinds' frame: segments + 1 points, the first at the origin.
    pub fn profile(&self) -> Vec<[f64; 2]> {
        let (d, a) = (self.depth_m, self.angle_deg.to_radians());
        // Along the chord, and its normal on the +Z side.
        let u = [a.cos(), a.sin()];
        let v = [-a.sin(), a.cos()];
        let Some(r) = self.curvature_radius_m else {
            return vec![[0.0, 0.0], [d * u[0], d * u[1]]];
        };
        let n = segments_per_slat(d, Some(r));
        let big_r = r.abs();
        let theta = 2.0 * (d / (2.0 * big_r)).asin();
        let side = r.signum();
        // Centre of the circle: on the chord's bisector, on the +Z side when r > 0.
        let h = big_r * (0.5 * theta).cos();
        let c = [
            0.5 * d * u[0] + side * h * v[0],
            0.5 * d * u[1] + side * h * v[1],
        ];
        (0..=n)
            .map(|k| {
                let t = -0.5 * theta + theta * k as f64 / n as f64;
                let (s, co) = t.sin_cos();
                [
                    c[0] + big_r * (s * u[0] - side * co * v[0]),
                    c[1] + big_r * (s * u[1] - side * co * v[1]),
                ]
            })
            .collect()
    }

    /// Triangles the blinds expand to.
    pub fn triangle_count(&self) -> u64 {
        self.count as u64 * segments_per_slat(self.depth_m, self.curvature_radius_m) as u64 * 2
    }

    /// A point of genblinds' frame in the scene.
    fn place(&self, x: f64, y: f64, z: f64) -> DVec3 {
        self.origin + x * self.out + y * self.width_dir + z * self.up
    }

    /// genblinds' polygons in its order (slat 1 at the bottom, segments from the pivot edge),
    /// each with genblinds' four vertices: (x₀, 0), (x₀, width), (x₁, width), (x₁, 0).
    pub fn polygons(&self) -> Vec<[DVec3; 4]> {
        let profile = self.profile();
        let mut out = Vec::with_capacity(self.count as usize * (profile.len() - 1));
        for n in 1..=self.count {
            let z0 = self.height_m * (n as f64 - 0.5) / self.count as f64;
            for s in profile.windows(2) {
                let (p, q) = (s[0], s[1]);
                out.push([
                    self.place(p[0], 0.0, z0 + p[1]),
                    self.place(p[0], self.width_m, z0 + p[1]),
                    self.place(q[0], self.width_m, z0 + q[1]),
                    self.place(q[0], 0.0, z0 + q[1]),
                ]);
            }
        }
        out
    }

    /// The triangle mesh: each of [`Self::polygons`] as (v0, v1, v2) and (v0, v2, v3), the
    /// vertices shared along a slat. Slats have no thickness; materials see both faces.
    pub fn mesh(&self) -> TriangleMesh {
        let profile = self.profile();
        let segs = profile.len() as u32 - 1;
        let mut mesh = TriangleMesh::default();
        mesh.positions
            .reserve(self.count as usize * profile.len() * 2);
        mesh.indices
            .reserve(self.count as usize * segs as usize * 2);
        for n in 1..=self.count {
            let z0 = self.height_m * (n as f64 - 0.5) / self.count as f64;
            let base = mesh.positions.len() as u32;
            for p in &profile {
                for y in [0.0, self.width_m] {
                    mesh.positions
                        .push(self.place(p[0], y, z0 + p[1]).as_vec3());
                }
            }
            for k in 0..segs {
                let [a, b, c, d] = [2 * k, 2 * k + 1, 2 * k + 3, 2 * k + 2].map(|i| base + i);
                mesh.indices.push([a, b, c]);
                mesh.indices.push([a, c, d]);
            }
        }
        mesh
    }

    /// The blinds `desc` (a `ShapeDesc::Blinds`) describes at `field`, every value checked.
    pub fn from_desc(ctx: &Context, field: &str, desc: &ShapeDesc) -> Result<Blinds, SceneError> {
        let ShapeDesc::Blinds {
            origin,
            width_dir,
            up,
            out,
            width,
            height,
            depth,
            spacing,
            count,
            angle_deg,
            curvature_radius,
            thickness,
        } = desc
        else {
            return Err(ctx.err(field, "not a Blinds shape"));
        };
        let f = |s: &str| format!("{field}.{s}");
        let origin = ctx.vec3(&f("origin"), *origin)?.as_dvec3();
        let width_dir = ctx
            .unit(&f("width_dir"), *width_dir)?
            .as_dvec3()
            .normalize();
        let up = ctx.unit(&f("up"), *up)?.as_dvec3().normalize();
        let out = ctx.unit(&f("out"), *out)?.as_dvec3().normalize();
        if up.dot(width_dir).abs() > PERPENDICULAR_COS {
            return Err(ctx.err(
                f("up"),
                format!(
                    "up must be perpendicular to width_dir (they make {:.3}°)",
                    up.angle_between(width_dir).to_degrees()
                ),
            ));
        }
        if out.dot(width_dir).abs() > PERPENDICULAR_COS || out.dot(up).abs() > PERPENDICULAR_COS {
            let n = width_dir.cross(up).normalize();
            return Err(ctx.err(
                f("out"),
                format!(
                    "out must be perpendicular to width_dir and up (the normal of the blinds' plane: ({:.4}, {:.4}, {:.4}) or its opposite)",
                    n.x, n.y, n.z
                ),
            ));
        }
        let width_m = ctx.positive(&f("width"), *width)?;
        let height_m = ctx.positive(&f("height"), *height)?;
        let depth_m = ctx.positive(&f("depth"), *depth)?;
        let count = slat_count(ctx, field, height_m, *spacing, *count)?;
        let angle_deg = ctx.finite(&f("angle_deg"), *angle_deg)?;
        if !(-90.0..=90.0).contains(&angle_deg) {
            return Err(ctx.err(
                f("angle_deg"),
                format!("the slat angle must be in [-90, 90] degrees, got {angle_deg}"),
            ));
        }
        let curvature_radius_m = match curvature_radius {
            None => None,
            Some(r) => {
                let r = ctx.finite(&f("curvature_radius"), *r)?;
                if r.abs() < 0.5 * depth_m {
                    return Err(ctx.err(
                        f("curvature_radius"),
                        format!(
                            "|r| = {} m is less than half the slat depth ({} m): no circle of that radius spans the slat; give None for flat slats",
                            r.abs(),
                            0.5 * depth_m
                        ),
                    ));
                }
                Some(r)
            }
        };
        let t = ctx.finite(&f("thickness"), *thickness)?;
        if t != 0.0 {
            return Err(ctx.err(
                f("thickness"),
                format!("only 0 is supported (slats are two-sided surfaces, as genblinds makes them), got {t}"),
            ));
        }
        let blinds = Blinds {
            origin,
            width_dir,
            up,
            out,
            width_m,
            height_m,
            depth_m,
            count,
            angle_deg,
            curvature_radius_m,
        };
        let n = blinds.triangle_count();
        if n > MAX_BLINDS_TRIANGLES {
            return Err(ctx.err(
                field,
                format!(
                    "the blinds would have {n} triangles ({count} slats × {} segments × 2), more than the {MAX_BLINDS_TRIANGLES} one Blinds shape may have: use fewer slats (a larger spacing) or a larger curvature radius",
                    segments_per_slat(depth_m, curvature_radius_m)
                ),
            ));
        }
        Ok(blinds)
    }
}

/// The number of slats from exactly one of `spacing` (m, rounded to height / spacing) and
/// `count`.
fn slat_count(
    ctx: &Context,
    field: &str,
    height_m: f64,
    spacing: Option<f64>,
    count: Option<u32>,
) -> Result<u32, SceneError> {
    match (spacing, count) {
        (Some(_), Some(_)) => Err(ctx.err(
            format!("{field}.spacing"),
            "give either spacing (m) or count (slats), not both",
        )),
        (None, None) => Err(ctx.err(
            format!("{field}.spacing"),
            "give the slats' spacing (m) or their count",
        )),
        (None, Some(0)) => Err(ctx.err(format!("{field}.count"), "must be at least 1, got 0")),
        (None, Some(n)) => Ok(n),
        (Some(s), None) => {
            let f = format!("{field}.spacing");
            let s = ctx.positive(&f, s)?;
            if s > height_m {
                return Err(ctx.err(
                    f,
                    format!("{s} m is more than the height ({height_m} m): not one slat fits"),
                ));
            }
            let n = (height_m / s).round();
            if n > MAX_BLINDS_TRIANGLES as f64 {
                return Err(ctx.err(
                    f,
                    format!(
                        "{s} m makes {n} slats, more than the {MAX_BLINDS_TRIANGLES} triangles one Blinds shape may have"
                    ),
                ));
            }
            Ok(n as u32)
        }
    }
}
