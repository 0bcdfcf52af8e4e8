//! Klems angle bases and the scattering matrices of a BSDF file in them.
//!
//! A basis divides the hemisphere into rings of polar angle, each cut into `nφ` patches whose
//! azimuths are centred at 360°·j/nφ (patch 0 straddles φ = 0). Directions are looked up as
//! Radiance's `fo_getndx` does (bsdf_m.c), so that a file reads the same here and there; the
//! projected solid angle of a patch is Λ = π(cos²θ_lo − cos²θ_hi)/nφ, and the patches of a
//! basis sum to π.

use glam::{Vec2, Vec3};

/// One ring of a basis: polar bounds as cos², the patch count, and the index of its first
/// patch.
#[derive(Clone, Debug)]
struct Ring {
    theta_lo_deg: f64,
    cos2_lo: f64,
    cos2_hi: f64,
    nphi: usize,
    first: usize,
    /// Projected solid angle of each patch of the ring, sr.
    proj_sr: f32,
}

/// A Klems angle basis (the three standard ones, or one a file defines).
#[derive(Clone, Debug)]
pub struct KlemsBasis {
    pub name: String,
    rings: Vec<Ring>,
    len: usize,
}

/// The standard bases: name, and each ring's lower polar bound in degrees with its φ count
/// (the last ring ends at 90°). Radiance's table (bsdf_m.c `abase_list`); the half basis has
/// 77 patches.
const STANDARD: [(&str, &[(f64, usize)]); 3] = [
    (
        "LBNL/Klems Full",
        &[
            (0.0, 1),
            (5.0, 8),
            (15.0, 16),
            (25.0, 20),
            (35.0, 24),
            (45.0, 24),
            (55.0, 24),
            (65.0, 16),
            (75.0, 12),
        ],
    ),
    (
        "LBNL/Klems Half",
        &[
            (0.0, 1),
            (6.5, 8),
            (19.5, 12),
            (32.5, 16),
            (45.5, 20),
            (58.5, 12),
            (71.5, 8),
        ],
    ),
    (
        "LBNL/Klems Quarter",
        &[(0.0, 1), (9.0, 8), (27.0, 12), (45.0, 12), (63.0, 8)],
    ),
];

/// Most patches a basis may have (the full basis has 145): a larger one would make matrices
/// of more than 10⁸ entries.
pub const MAX_PATCHES: usize = 10_000;

impl KlemsBasis {
    /// The standard basis of this name (compared without case, as Radiance does).
    pub fn standard(name: &str) -> Option<Self> {
        STANDARD
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(name))
            .map(|(n, rings)| Self::from_rings(n, rings).expect("standard bases are valid"))
    }

    /// A basis from rings given as (lower polar bound in degrees, φ count), in increasing
    /// order from 0°, the last ending at 90°.
    pub fn from_rings(name: &str, rings: &[(f64, usize)]) -> Result<Self, String> {
        if rings.is_empty() {
            return Err("the basis has no rings".into());
        }
        let mut out = Vec::with_capacity(rings.len());
        let mut first = 0usize;
        for (k, &(lo, nphi)) in rings.iter().enumerate() {
            let hi = rings.get(k + 1).map_or(90.0, |r| r.0);
            if k == 0 && lo != 0.0 {
                return Err(format!("its first ring starts at {lo}°, not 0°"));
            }
            if !(lo.is_finite() && hi.is_finite() && lo < hi && hi <= 90.0) {
                return Err(format!(
                    "ring {} spans {lo}° to {hi}°; rings must increase from 0° to 90°",
                    k + 1
                ));
            }
            if nphi == 0 || (nphi == 1 && lo > 0.0) {
                return Err(format!(
                    "ring {} has {nphi} patches in φ; only the ring about the normal may have one",
                    k + 1
                ));
            }
            if first + nphi > MAX_PATCHES {
                return Err(format!(
                    "it has more than {MAX_PATCHES} patches; candela refuses larger bases"
                ));
            }
            let c2 = |deg: f64| deg.to_radians().cos().powi(2);
            let (cos2_lo, cos2_hi) = (c2(lo), if hi >= 90.0 { 0.0 } else { c2(hi) });
            out.push(Ring {
                theta_lo_deg: lo,
                cos2_lo,
                cos2_hi,
                nphi,
                first,
                proj_sr: (std::f64::consts::PI * (cos2_lo - cos2_hi) / nphi as f64) as f32,
            });
            first += nphi;
        }
        Ok(Self {
            name: name.to_string(),
            rings: out,
            len: first,
        })
    }

    /// Number of patches.
    #[inline]
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the basis has no patches (never, once built).
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The patch holding the direction `v` of the upper hemisphere (v.z ≥ 0, unit); `v.z`
    /// below 0 or a direction in the plane counts as the outermost ring.
    pub fn index(&self, v: Vec3) -> usize {
        let z = (v.z as f64).clamp(0.0, 1.0);
        let pol = z.acos().to_degrees();
        let li = self
            .rings
            .iter()
            .rposition(|r| r.theta_lo_deg <= pol)
            .unwrap_or(0);
        let r = &self.rings[li];
        let mut azi = (v.y as f64).atan2(v.x as f64).to_degrees();
        if azi < 0.0 {
            azi += 360.0;
        }
        let mut j = (azi / 360.0 * r.nphi as f64 + 0.5) as usize;
        if j >= r.nphi {
            j = 0;
        }
        r.first + j
    }

    /// Projected solid angle of patch `i`, sr.
    #[inline]
    pub fn proj_sr(&self, i: usize) -> f32 {
        self.rings[self.ring_of(i)].proj_sr
    }

    fn ring_of(&self, i: usize) -> usize {
        self.rings
            .iter()
            .rposition(|r| r.first <= i)
            .expect("patch index within the basis")
    }

    /// A direction of the upper hemisphere in patch `i`, uniform in projected solid angle for
    /// `u` uniform in [0, 1)².
    pub fn sample(&self, i: usize, u: Vec2) -> Vec3 {
        let r = &self.rings[self.ring_of(i)];
        let j = (i - r.first) as f64;
        let cos2 = r.cos2_lo + (r.cos2_hi - r.cos2_lo) * u.x as f64;
        let cos = cos2.max(0.0).sqrt();
        let sin = (1.0 - cos2).max(0.0).sqrt();
        let phi = std::f64::consts::TAU * (j + u.y as f64 - 0.5) / r.nphi as f64;
        Vec3::new(
            (sin * phi.cos()) as f32,
            (sin * phi.sin()) as f32,
            cos as f32,
        )
    }

    /// The direction at the centre of patch `i` (mid-polar angle, centre azimuth).
    pub fn centre(&self, i: usize) -> Vec3 {
        self.sample(i, Vec2::splat(0.5))
    }
}

/// One scattering matrix: f[o][i] in sr⁻¹ for incident patch i of `inc` and outgoing patch o
/// of `out`, with each row's sampling distribution over the incident patches.
#[derive(Clone, Debug)]
pub struct KlemsMatrix {
    pub inc: KlemsBasis,
    pub out: KlemsBasis,
    /// f, row-major by outgoing patch: `f[o * inc.len() + i]`, sr⁻¹.
    pub f: Vec<f32>,
    /// Per row o: Σ_i f[o][i] Λ_i (the reciprocal albedo toward o; no unit).
    row_sum: Vec<f32>,
    /// Per row o: the cumulative distribution of f[o][i] Λ_i over i (last entry 1).
    row_cdf: Vec<f32>,
}

impl KlemsMatrix {
    /// A matrix from its values `f[o * inc.len() + i]`.
    pub fn new(inc: KlemsBasis, out: KlemsBasis, f: Vec<f32>) -> Self {
        let (ni, no) = (inc.len(), out.len());
        debug_assert_eq!(f.len(), ni * no);
        let mut row_sum = vec![0.0f32; no];
        let mut row_cdf = vec![0.0f32; ni * no];
        let lambda: Vec<f64> = (0..ni).map(|i| inc.proj_sr(i) as f64).collect();
        for o in 0..no {
            let row = &f[o * ni..(o + 1) * ni];
            let mut acc = 0.0f64;
            let cdf = &mut row_cdf[o * ni..(o + 1) * ni];
            for i in 0..ni {
                acc += row[i] as f64 * lambda[i];
                cdf[i] = acc as f32;
            }
            row_sum[o] = acc as f32;
            if acc > 0.0 {
                for (i, c) in cdf.iter_mut().enumerate() {
                    *c = if i + 1 == ni {
                        1.0
                    } else {
                        (*c as f64 / acc) as f32
                    };
                }
            }
        }
        Self {
            inc,
            out,
            f,
            row_sum,
            row_cdf,
        }
    }

    /// The matrix of the opposite direction by reciprocity: light entering where this one's
    /// leaves. Its incident patch for a direction is this one's outgoing patch turned by 180°
    /// about the normal (and the other way round), which maps patch centres onto patch
    /// centres when every ring has an even φ count (all standard bases do).
    pub fn reciprocal(&self) -> Result<Self, String> {
        if let Some(b) = [&self.inc, &self.out]
            .into_iter()
            .find(|b| b.rings.iter().any(|r| r.nphi % 2 == 1 && r.nphi > 1))
        {
            return Err(format!(
                "basis '{}' has a ring with an odd φ count, so the missing direction cannot be \
                 made from the given one by reciprocity; give both",
                b.name
            ));
        }
        let (inc, out) = (self.out.clone(), self.inc.clone());
        let (ni, no) = (inc.len(), out.len());
        let mut f = vec![0.0f32; ni * no];
        for o in 0..no {
            let b = out.centre(o);
            // This matrix's incident direction is the new outgoing one turned by 180°.
            let i_old = self.inc.index(Vec3::new(-b.x, -b.y, b.z));
            for i in 0..ni {
                let a = inc.centre(i);
                let o_old = self.out.index(Vec3::new(-a.x, -a.y, a.z));
                f[o * ni + i] = self.f[o_old * self.inc.len() + i_old];
            }
        }
        Ok(Self::new(inc, out, f))
    }

    /// f for incident index vector `a` and outgoing index vector `b` (both z ≥ 0), sr⁻¹.
    #[inline]
    pub fn value(&self, a: Vec3, b: Vec3) -> f32 {
        self.f[self.out.index(b) * self.inc.len() + self.inc.index(a)]
    }

    /// Σ_i f[o(b)][i] Λ_i: the directional albedo toward outgoing `b` (by reciprocity, the
    /// fraction scattered by light arriving from there).
    #[inline]
    pub fn row_sum(&self, b: Vec3) -> f32 {
        self.row_sum[self.out.index(b)]
    }

    /// An incident index vector for outgoing `b`, drawn in proportion to f Λ over the patches
    /// and uniformly in projected solid angle within the patch; `None` when the row is zero.
    pub fn sample(&self, b: Vec3, uc: f32, u: Vec2) -> Option<Vec3> {
        let o = self.out.index(b);
        if self.row_sum[o] <= 0.0 {
            return None;
        }
        let ni = self.inc.len();
        let cdf = &self.row_cdf[o * ni..(o + 1) * ni];
        let i = cdf.partition_point(|&c| c <= uc).min(ni - 1);
        Some(self.inc.sample(i, u))
    }

    /// Largest hemispherical sum Σ_o f[o][i] Λ_o over the incident patches i (what a ray
    /// arriving through patch i scatters in all), with that patch.
    pub fn max_hemispherical(&self) -> (f64, usize) {
        let mut best = (0.0f64, 0usize);
        for i in 0..self.inc.len() {
            let s = self.hemispherical(i);
            if s > best.0 {
                best = (s, i);
            }
        }
        best
    }

    /// Σ_o f[o][i] Λ_o: the fraction of light arriving through incident patch `i` that the
    /// matrix scatters.
    pub fn hemispherical(&self, i: usize) -> f64 {
        let ni = self.inc.len();
        (0..self.out.len())
            .map(|o| self.f[o * ni + i] as f64 * self.out.proj_sr(o) as f64)
            .sum()
    }

    /// The polar and azimuth angles (degrees) of the centre of incident patch `i`.
    pub fn incident_angles_deg(&self, i: usize) -> (f64, f64) {
        let v = self.inc.centre(i);
        let theta = (v.z as f64).acos().to_degrees();
        let phi = (v.y as f64)
            .atan2(v.x as f64)
            .to_degrees()
            .rem_euclid(360.0);
        (theta, phi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn standard_bases_have_their_patch_counts_and_cover_the_projected_hemisphere() {
        for (name, n) in [
            ("LBNL/Klems Full", 145),
            ("LBNL/Klems Half", 77),
            ("lbnl/klems quarter", 41),
        ] {
            let b = KlemsBasis::standard(name).unwrap();
            assert_eq!(b.len(), n, "{name}");
            let total: f64 = (0..n).map(|i| b.proj_sr(i) as f64).sum();
            assert!(
                (total - std::f64::consts::PI).abs() < 1e-5,
                "{name}: {total}"
            );
        }
        assert!(KlemsBasis::standard("LBNL/Klems Eighth").is_none());
    }

    #[test]
    fn sampled_points_fall_in_their_own_patch() {
        let b = KlemsBasis::standard("LBNL/Klems Full").unwrap();
        for i in 0..b.len() {
            for u in [
                Vec2::new(0.01, 0.02),
                Vec2::new(0.5, 0.5),
                Vec2::new(0.98, 0.97),
            ] {
                assert_eq!(b.index(b.sample(i, u)), i, "patch {i} at {u}");
            }
        }
        // Azimuths are centred on the patch: patch 1 (second ring, j = 0) straddles φ = 0.
        assert_eq!(b.index(Vec3::new(0.2, -0.01, 0.98).normalize()), 1);
        assert_eq!(b.index(Vec3::Z), 0);
    }

    #[test]
    fn reciprocal_of_reciprocal_is_the_matrix_and_diagonal_stays_diagonal() {
        let b = KlemsBasis::standard("LBNL/Klems Quarter").unwrap();
        let n = b.len();
        let f: Vec<f32> = (0..n * n).map(|k| ((k * 37) % 101) as f32 * 0.01).collect();
        let m = KlemsMatrix::new(b.clone(), b.clone(), f);
        let back = m.reciprocal().unwrap().reciprocal().unwrap();
        assert_eq!(back.f, m.f);
        let diag: Vec<f32> = (0..n * n)
            .map(|k| if k / n == k % n { 1.0 } else { 0.0 })
            .collect();
        let d = KlemsMatrix::new(b.clone(), b, diag.clone());
        assert_eq!(d.reciprocal().unwrap().f, diag);
    }

    #[test]
    fn custom_bases_are_checked() {
        assert!(KlemsBasis::from_rings("x", &[(0.0, 1), (45.0, 4)]).is_ok());
        assert!(KlemsBasis::from_rings("x", &[(5.0, 1)]).is_err());
        assert!(KlemsBasis::from_rings("x", &[(0.0, 1), (30.0, 1)]).is_err());
        assert!(KlemsBasis::from_rings("x", &[(0.0, 1), (30.0, 4), (20.0, 4)]).is_err());
        assert!(KlemsBasis::from_rings("x", &[(0.0, 1), (30.0, 20_000)]).is_err());
    }
}
