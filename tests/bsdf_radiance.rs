//! A room lit through a window given as a BSDF XML file (Klems half basis: 30 % Lambertian
//! and a 20 % lobe about the straight-through direction, made by bsdf2klems), candela's
//! `BsdfFile` against Radiance's `BSDF` primitive with the same file (rtrace -I from PyPI
//! `pyradiance`), under a uniform sky and with the sun at three positions. The sun reaches the
//! room in both only through the file: at the window both evaluate it at the sun's exact
//! direction (candela by light sampling, Radiance by its direct calculation at the window), and
//! both spread what passes over the file's outgoing patch.
//!
//! rtrace samples every part of the BSDF (`-st 0`): with its default threshold it renders the
//! lobe as Lambertian where it is weak, and the work plane 1 m from the window reads 6 % less.
//!
//! Fails without the Python venv (scripts/setup_python.sh, or CANDELA_PYTHON), as the other
//! reference tests do.

mod common;

use common::radiance_room::{compare, Sun, Tolerance, Window};
use std::path::Path;

fn window() -> Window {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/bsdf/klems_half_lobe.xml");
    Window {
        // thickness 0, the file, up = +z, no function file; the normal points into the room.
        radiance: "void BSDF win 6 0 klems_half_lobe.xml 0 0 1 . 0 0".into(),
        candela: "\"win\": BsdfFile(file: \"klems_half_lobe.xml\", up: (0, 0, 1))".into(),
        files: vec![file],
        normal_in: true,
        // Sample every non-Lambertian part (-st 0): by default rtrace treats a lobe whose
        // scattered fraction toward the viewer is below 0.15 as Lambertian, which moved 6 % of
        // the light near this window. -ss 16: 16 samples of each such lobe per hit.
        rtrace: &["-st", "0", "-ss", "16"],
    }
}

#[test]
fn a_bsdf_window_under_a_uniform_sky_agrees_with_radiance() {
    let tol = Tolerance {
        z_max: 4.0,
        max_rel_se: 0.01,
        max_rel_diff: None,
    };
    let failures = compare("bsdf_sky", &window(), (1.0, None), 1 << 19, 24, &tol);
    assert!(failures.is_empty(), "{}", failures.join(", "));
}

#[test]
fn the_sun_through_a_bsdf_window_agrees_with_radiance_to_the_basis_resolution() {
    // Sun radiance 6.5·10⁶ W/(sr m²) per channel: about 80 klx normal to it. Radiance's direct
    // calculation at a BSDF surface averages the file over view directions jittered by
    // √(smallest projected solid angle of the basis) = 0.185 here (m_bsdf.c bsdf_jitter), so its
    // sun patch is blurred into the neighbouring outgoing patches; candela reads the file as
    // tabulated (bsdf_file.rs checks that by quadrature to 0.01 %). That blur alone moves the
    // direct sun at 1 m from the window by −0.6 % and at 2 m by +0.6 %; the differences seen
    // here reach −2.5 % and +1.1 % at those points: 3 % is the bound.
    let tol = Tolerance {
        z_max: f64::INFINITY,
        max_rel_se: 0.02,
        max_rel_diff: Some(0.03),
    };
    let mut failures = Vec::new();
    for (k, d) in [[0.3, -0.8, 0.5], [-0.5, -0.6, 0.6], [0.1, -0.95, 0.3f64]]
        .into_iter()
        .enumerate()
    {
        let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let sun = Sun {
            dir: [d[0] / n, d[1] / n, d[2] / n],
            radiance: 6.5e6,
        };
        let name = format!("bsdf_sun{k}");
        failures.extend(compare(
            &name,
            &window(),
            (0.0, Some(sun)),
            1 << 18,
            24,
            &tol,
        ));
    }
    assert!(failures.is_empty(), "{}", failures.join(", "));
}
