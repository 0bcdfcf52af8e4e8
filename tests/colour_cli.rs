//! The library side of `candela spectrum` / `candela convert`: output shape and the JSON
//! keys documented in docs/colour.md.

use candela::cli_colour::{convert_command, spectrum_command};
use candela::colour::tables::Observer;

#[test]
fn spectrum_text_and_json_keys() {
    let text = spectrum_command("FL2", Observer::Cie1931_2, false).unwrap();
    println!("{text}");
    for k in [
        "XYZ (Y = 100)",
        "xy",
        "u'v'",
        "CCT, Duv (Ohno 2013)",
        "S/P ratio",
        "sRGB encoded",
        "Ra",
    ] {
        assert!(text.contains(k), "missing {k}");
    }
    let j: serde_json::Value =
        serde_json::from_str(&spectrum_command("LED-B3", Observer::Cie1964_10, true).unwrap())
            .unwrap();
    for k in [
        "source",
        "description",
        "observer",
        "xyz",
        "xyz_absolute",
        "luminance_cd_m2_if_radiance",
        "xy",
        "upvp",
        "uv_1960",
        "cct_k",
        "duv",
        "cct_robertson_k",
        "duv_robertson",
        "luminous_efficacy_lm_per_w",
        "sp_ratio",
        "srgb_linear",
        "srgb_encoded",
        "cri",
    ] {
        assert!(j.get(k).is_some(), "JSON key {k} missing");
    }
    assert_eq!(j["cri"]["r"].as_array().unwrap().len(), 14);
    println!("{}", convert_command(1.0, "footlambert", "nit").unwrap());
}
