//! The data-sheet figures of a photometry: integrated and stated flux, peak intensity and its
//! direction, beam (50 %) and field (10 %) angles.

use super::{spread_angle, Photometry};

/// Summary figures of a photometry.
#[derive(Clone, Debug)]
pub struct Summary {
    pub integrated_lumens: f64,
    pub stated_lumens: Option<f64>,
    pub max_cd: f64,
    /// File angles (plane, in-plane) of the maximum, degrees.
    pub max_at: (f64, f64),
    /// Beam (50 %) and field (10 %) angles in the C0–C180 and C90–C270 planes, degrees.
    pub beam: [f64; 2],
    pub field: [f64; 2],
}

/// The summary figures of `p`, from its expanded [`Distribution`](super::Distribution).
pub fn summarise(p: &Photometry) -> Summary {
    let d = p.distribution();
    let (max_cd, a, b) = d.max_direction();
    Summary {
        integrated_lumens: d.lumens(),
        stated_lumens: p.stated_lumens,
        max_cd,
        max_at: (a, b),
        beam: [spread_angle(&d, 0.0, 0.5), spread_angle(&d, 90.0, 0.5)],
        field: [spread_angle(&d, 0.0, 0.1), spread_angle(&d, 90.0, 0.1)],
    }
}
