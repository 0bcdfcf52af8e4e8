//! Where light tracing (`integrator::light_path`) starts and aims its paths, fixed when the
//! scene is built: the lights it starts from with their cdf, and the bounding spheres of the
//! objects that can scatter specularly, toward which emission directions are sampled.

use crate::geometry::SceneGeometry;
use crate::light::Light;
use crate::sampling::choose_by_weight;
use glam::{Vec2, Vec3};

/// The lights light tracing starts paths from (all but environments), chosen in
/// proportion to their luminous power, and where their paths are aimed.
#[derive(Clone, Debug)]
pub struct CausticLights {
    /// Light indices (into [`super::World::lights`]).
    pub lights: Vec<u32>,
    /// Cumulative distribution over `lights`, in proportion to their luminous power.
    pub cdf: Vec<f32>,
    /// Per light of the world: whether it is one of `lights`.
    pub handled: Vec<bool>,
    /// Bounding spheres (centre, radius) of the objects with a delta lobe. A light path is
    /// only light tracing's if its first scattering is specular, so emission directions are
    /// sampled only toward these (uniformly within the cones they subtend), not wasted on
    /// the rest of the scene.
    pub targets: Vec<(Vec3, f32)>,
    /// Bounding sphere (centre, radius) of the scene: paths of distant lights start outside it.
    pub scene: (Vec3, f32),
}

/// Most target spheres kept separately; more are merged into one.
const MAX_TARGETS: usize = 16;

/// A bounding sphere of a shape (of its bounding box, for flat and meshed shapes).
pub fn bounding_sphere(shape: &crate::geometry::Shape) -> Option<(Vec3, f32)> {
    use crate::geometry::Shape;
    let from_points = |pts: &mut dyn Iterator<Item = Vec3>| {
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for p in pts {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        (lo.cmple(hi).all()).then(|| sphere_of_box(lo, hi))
    };
    match shape {
        // The same slack as boxes get (rays may hit a hair outside the exact radius).
        Shape::Sphere { center, radius } | Shape::Disk { center, radius, .. } => {
            Some((*center, *radius * (1.0 + 1e-4) + 1e-6))
        }
        Shape::Quad {
            origin,
            edge_u,
            edge_v,
        } => from_points(
            &mut [
                *origin,
                *origin + *edge_u,
                *origin + *edge_v,
                *origin + *edge_u + *edge_v,
            ]
            .into_iter(),
        ),
        Shape::Mesh(m) => from_points(&mut m.positions.iter().copied()),
    }
}

fn sphere_of_box(lo: Vec3, hi: Vec3) -> (Vec3, f32) {
    let c = 0.5 * (lo + hi);
    // A little slack: the sphere must contain every point a ray can hit.
    (c, 0.5 * (hi - lo).length() * (1.0 + 1e-4) + 1e-6)
}

/// Whether light tracing may have work in a scene, judged before its lights are built (for the
/// memory guard, which then counts light tracing's buffers): some object can scatter
/// specularly (`targets`, the bounding spheres [`CausticLights::new`] gets) and some light
/// other than an environment exists (an emitting object, `area_lights`, or another light).
/// [`CausticLights::new`] then returns `Some` unless every such light has no power.
pub fn may_trace(targets: &[(Vec3, f32)], area_lights: bool, other_lights: bool) -> bool {
    targets
        .iter()
        .any(|(c, r)| c.is_finite() && r.is_finite() && *r > 0.0)
        && (area_lights || other_lights)
}

impl CausticLights {
    /// `targets`: bounding spheres of the objects whose material has a delta lobe. None when
    /// light tracing has nothing to do: no such object, or no light other than an environment with
    /// power.
    pub fn new(
        lights: &[Light],
        mut targets: Vec<(Vec3, f32)>,
        geom: &SceneGeometry,
        scene_radius: f32,
    ) -> Option<Self> {
        targets.retain(|(c, r)| c.is_finite() && r.is_finite() && *r > 0.0);
        if targets.is_empty() {
            return None;
        }
        if targets.len() > MAX_TARGETS {
            let lo = targets
                .iter()
                .fold(Vec3::splat(f32::INFINITY), |a, (c, r)| a.min(*c - *r));
            let hi = targets
                .iter()
                .fold(Vec3::splat(f32::NEG_INFINITY), |a, (c, r)| a.max(*c + *r));
            targets = vec![sphere_of_box(lo, hi)];
        }
        let mut chosen = Vec::new();
        let mut powers = Vec::new();
        for (i, l) in lights.iter().enumerate() {
            let p = l.power_lm(geom, scene_radius);
            if l.flags().can_emit_paths() && p > 0.0 && p.is_finite() {
                chosen.push(i as u32);
                powers.push(p);
            }
        }
        if chosen.is_empty() {
            return None;
        }
        let cdf = crate::sampling::cdf_from_weights(&powers);
        let mut handled = vec![false; lights.len()];
        for &i in &chosen {
            handled[i as usize] = true;
        }
        let (lo, hi) = geom.bounds();
        let scene = if lo.is_finite() && hi.is_finite() && hi.cmpge(lo).all() {
            sphere_of_box(lo, hi)
        } else {
            (Vec3::ZERO, scene_radius)
        };
        Some(Self {
            lights: chosen,
            cdf,
            handled,
            targets,
            scene,
        })
    }

    /// Where a path of a distant light travelling along `dir` starts: a point of the disks the
    /// targets' bounding spheres project onto a plane normal to `dir` (a disk chosen in
    /// proportion to its area, uniform within it), moved back along `dir` to outside the
    /// scene. Returns the origin and the density per unit area normal to `dir`: (number of
    /// disks containing the point) / (sum of the disks' areas).
    pub fn sample_parallel(&self, dir: Vec3, uc: f32, u: Vec2) -> Option<(Vec3, f32)> {
        use std::f32::consts::PI;
        let area = |&(_, r): &(Vec3, f32)| PI * r * r;
        let total: f32 = self.targets.iter().map(area).sum();
        if total.is_nan() || total <= 0.0 {
            return None;
        }
        let chosen = choose_by_weight(
            self.targets.iter().map(|t| area(t) as f64),
            (uc * total) as f64,
        );
        let (c, r) = self.targets[chosen];
        let (t, b) = dir.any_orthonormal_pair();
        let (s, phi) = crate::sampling::uniform_disk_polar(u);
        let rad = r * s;
        let p = c + rad * (phi.cos() * t + phi.sin() * b);
        let count = 1 + self
            .targets
            .iter()
            .enumerate()
            .filter(|&(k, &(cj, rj))| {
                let v = p - cj;
                k != chosen && (v - v.dot(dir) * dir).length_squared() <= rj * rj
            })
            .count();
        // Back along the line to outside the scene's bounding sphere.
        let (cs, rs) = self.scene;
        let back = (p - cs).dot(dir) + 1.01 * rs + 1e-3;
        Some((p - back * dir, count as f32 / total))
    }

    /// A direction from `p` toward the targets and its density (solid angle): a cone chosen in
    /// proportion to its solid angle, uniform within it, so the density is (number of cones
    /// containing the direction) / (sum of the cones' solid angles). Uniform over the sphere
    /// when the cones would cover more than it.
    pub fn sample_direction(&self, p: Vec3, uc: f32, u: Vec2) -> Option<(Vec3, f32)> {
        use glam::DVec3;
        use std::f64::consts::PI;
        // In f64 and without cancellation, so that small or distant targets (r/d down to
        // ~1e-150) keep their exact cones: per cone, the axis, sin²θmax = r²/d² (≥ 1: the
        // point is inside, the cone is the whole sphere) and 1 − cos θmax = s / (1 + √(1 − s)).
        let p = p.as_dvec3();
        let mut cones = [(DVec3::ZERO, 0.0f64, 0.0f64); MAX_TARGETS];
        let mut total = 0.0f64;
        for (k, &(c, r)) in self.targets.iter().enumerate() {
            let d = c.as_dvec3() - p;
            let dist2 = d.length_squared();
            let r = r as f64;
            let sin2 = if dist2 > 0.0 { r * r / dist2 } else { 1.0 };
            let omc = if sin2 >= 1.0 {
                2.0
            } else {
                sin2 / (1.0 + (1.0 - sin2).sqrt())
            };
            let axis = if dist2 > 0.0 {
                d / dist2.sqrt()
            } else {
                DVec3::Z
            };
            cones[k] = (axis, sin2, omc);
            total += 2.0 * PI * omc;
        }
        let cones = &cones[..self.targets.len()];
        if total.is_nan() || total <= 0.0 {
            return None;
        }
        if total >= 4.0 * PI {
            return Some((
                crate::sampling::uniform_sphere(u),
                crate::sampling::UNIFORM_SPHERE_PDF,
            ));
        }
        // Choose a cone in proportion to its solid angle.
        let chosen = choose_by_weight(cones.iter().map(|c| 2.0 * PI * c.2), uc as f64 * total);
        let (axis, _, omc) = cones[chosen];
        // Uniform within the cone: 1 − cos θ uniform in [0, 1 − cos θmax].
        let (cos_t, sin_t, phi) = crate::sampling::uniform_cone(u.x as f64, u.y as f64, omc);
        let (t, b) = axis.any_orthonormal_pair();
        let dir = (sin_t * phi.cos() * t + sin_t * phi.sin() * b + cos_t * axis).normalize();
        // Inside cone k: the whole sphere, or on the axis' side within sin²θ ≤ sin²θmax.
        let count = 1 + cones
            .iter()
            .enumerate()
            .filter(|&(k, c)| {
                k != chosen
                    && (c.1 >= 1.0
                        || (dir.dot(c.0) > 0.0 && dir.cross(c.0).length_squared() <= c.1))
            })
            .count();
        Some((dir.as_vec3(), (count as f64 / total) as f32))
    }

    /// Whether emission from light `light` reached through a caustic chain is light tracing's
    /// part of path space (and so not the camera path's).
    #[inline]
    pub fn handles(&self, light: usize) -> bool {
        self.handled.get(light).copied().unwrap_or(false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::uniform_sphere;

    fn lights_with_targets(targets: Vec<(Vec3, f32)>) -> CausticLights {
        CausticLights {
            lights: vec![0],
            cdf: vec![1.0],
            handled: vec![true],
            targets,
            scene: (Vec3::ZERO, 1e5),
        }
    }

    /// E[1{dir in a cone}/pdf] over the sampled directions is the solid angle of the union of
    /// the cones, which uniform sampling of the sphere measures independently.
    #[test]
    fn target_direction_density_integrates_to_the_union_of_the_cones() {
        let p = Vec3::new(0.1, 2.0, -0.3);
        let targets = vec![
            (Vec3::new(0.0, 0.0, 0.0), 0.5),
            (Vec3::new(0.4, 0.2, 0.1), 0.3),
            (Vec3::new(-2.0, 2.5, 1.0), 0.2),
        ];
        let c = lights_with_targets(targets.clone());
        let inside = |d: Vec3| {
            targets.iter().any(|&(ctr, r)| {
                let v = ctr - p;
                let cos_max = (1.0 - r * r / v.length_squared()).sqrt();
                d.dot(v.normalize()) >= cos_max
            })
        };
        let n = 400_000;
        let (mut est, mut est2) = (0.0f64, 0.0f64);
        let mut rng = 0x1234_5678_u64;
        let mut u = || {
            rng = crate::sampling::mix64(rng.wrapping_add(0x9e37_79b9_7f4a_7c15));
            (rng >> 40) as f32 / (1u64 << 24) as f32
        };
        for _ in 0..n {
            let (d, pdf) = c
                .sample_direction(p, u(), Vec2::new(u(), u()))
                .expect("a direction");
            assert!(pdf > 0.0 && pdf.is_finite());
            if inside(d) {
                est += 1.0 / pdf as f64;
                est2 += 1.0 / (pdf as f64 * pdf as f64);
            }
        }
        // Midpoint quadrature over (z, φ), where the sphere's measure is uniform.
        let grid = |m: usize| {
            let mut inside_cells = 0usize;
            for i in 0..m {
                for j in 0..m {
                    let d = uniform_sphere(Vec2::new(
                        (i as f32 + 0.5) / m as f32,
                        (j as f32 + 0.5) / m as f32,
                    ));
                    inside_cells += inside(d) as usize;
                }
            }
            4.0 * std::f64::consts::PI * inside_cells as f64 / (m * m) as f64
        };
        let uniform = grid(3000);
        let coarse = grid(2000);
        // The estimate's standard error from the sample variance of 1{inside}/pdf. The
        // reference's own error (the grid cells cut by the cones' rims) must be far below it:
        // the 3000² and 2000² grids agree to a fifth of it.
        let nf = n as f64;
        let est = est / nf;
        let se = ((est2 / nf - est * est).max(0.0) / (nf - 1.0)).sqrt();
        println!("union of the cones: {est} ± {se} sr, quadrature {uniform} sr (2000²: {coarse})");
        assert!(
            (uniform - coarse).abs() < 0.2 * se,
            "{uniform} vs {coarse} sr"
        );
        assert!(
            (est - uniform).abs() <= 5.0 * se && se < 0.003 * uniform,
            "{est} ± {se} vs {uniform} sr"
        );
    }

    #[test]
    fn small_distant_targets_keep_their_exact_cones() {
        // r/d from 1e-2 down to 1e-7: f32's 1 − √(1 − r²/d²) loses the cone below ~2e-4 (and
        // collapsed it to nothing below 1.7e-4, dropping such a target's caustics).
        for (r, d) in [(0.01f32, 1.0f32), (0.01, 100.0), (0.01, 1e4), (1e-3, 1e4)] {
            let c = lights_with_targets(vec![(Vec3::new(0.0, 0.0, d), r)]);
            let omega = std::f64::consts::PI * (r as f64 / d as f64).powi(2);
            for k in 0..64 {
                let u = |i: u32| ((k * 7 + i * 13) % 64) as f32 / 64.0 + 1.0 / 128.0;
                let (dir, pdf) = c
                    .sample_direction(Vec3::ZERO, u(0), Vec2::new(u(1), u(2)))
                    .unwrap();
                // Density: 1/Ω within 1e-3 (Ω ≈ π r²/d² for small cones).
                assert!(
                    ((pdf as f64 * omega) - 1.0).abs() < 1e-3,
                    "r {r}, d {d}: pdf·Ω = {}",
                    pdf as f64 * omega
                );
                // The direction passes within the (slightly padded) sphere.
                let miss = dir
                    .as_dvec3()
                    .cross(glam::DVec3::new(0.0, 0.0, d as f64))
                    .length();
                assert!(
                    miss <= r as f64 * 1.001 + 1e-6,
                    "r {r}, d {d}: passes at {miss}"
                );
            }
        }
    }

    #[test]
    fn a_point_inside_a_target_samples_the_whole_sphere() {
        let c = lights_with_targets(vec![(Vec3::ZERO, 1.0)]);
        let (_, pdf) = c
            .sample_direction(Vec3::new(0.1, 0.2, 0.0), 0.3, Vec2::new(0.4, 0.5))
            .unwrap();
        assert!((pdf - 1.0 / (4.0 * std::f32::consts::PI)).abs() < 1e-7);
    }
}
