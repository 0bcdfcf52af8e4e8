"""candela.colour on arrays agrees with colour-science 0.4.7 (the pinned reference) on random
smooth spectra, to the tolerances tests/colour_science.rs and tests/colour_health.rs hold the
Rust library to; α-opic quantities meet their definitions (D65's DER is 1)."""

import warnings

import numpy as np
import pytest

import candela
from candela import colour as cc

warnings.filterwarnings("ignore")
colour = pytest.importorskip("colour")

WL = np.arange(360.0, 831.0)
CMFS = {
    "1931": colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"],
    "1964": colour.MSDS_CMFS["CIE 1964 10 Degree Standard Observer"],
}


def smooth_spectra(n, seed):
    """n positive spectra on 360–830 nm: sums of three Gaussians over a pedestal."""
    rng = np.random.default_rng(seed)
    s = np.full((n, WL.size), 0.02)
    for _ in range(3):
        mu = rng.uniform(380, 780, (n, 1))
        sigma = rng.uniform(10, 120, (n, 1))
        s += rng.uniform(0.1, 1.0, (n, 1)) * np.exp(-0.5 * ((WL - mu) / sigma) ** 2)
    return s


def sd(values):
    return colour.SpectralDistribution(values, WL)


def rel_dev(a, b):
    return np.max(np.abs(a - b)) / np.max(np.abs(b))


@pytest.mark.parametrize("observer", ["1931", "1964"])
def test_xyz_agrees_with_colour_science(observer):
    s = smooth_spectra(40, 1)
    cmfs = CMFS[observer]
    absolute = cc.sd_to_xyz(WL, s, "absolute", observer=observer)
    emissive = cc.sd_to_xyz(WL, s, "emissive", observer=observer)
    astm = cc.sd_to_xyz(WL, s, "emissive", observer=observer, method="astm-e308")
    d65 = colour.SDS_ILLUMINANTS["D65"].copy().align(colour.SpectralShape(360, 830, 1))
    refl = s / s.max(axis=1, keepdims=True)
    relative = cc.sd_to_xyz(WL, refl, "relative", illuminant=(WL, d65.values), observer=observer)
    assert absolute.shape == (40, 3)
    for i in range(len(s)):
        ref_abs = colour.sd_to_XYZ(sd(s[i]), cmfs, k=683, method="Integration")
        ref_em = colour.sd_to_XYZ(sd(s[i]), cmfs, method="Integration")
        ref_astm = colour.sd_to_XYZ(sd(s[i]), cmfs)
        ref_rel = colour.sd_to_XYZ(sd(refl[i]), cmfs, d65, method="Integration")
        assert rel_dev(absolute[i], ref_abs) < 1e-10
        assert rel_dev(emissive[i], ref_em) < 1e-10
        assert rel_dev(astm[i], ref_astm) < 1e-10
        assert rel_dev(relative[i], ref_rel) < 1e-10
    # One spectrum (W,) gives one XYZ (3,).
    assert np.array_equal(cc.sd_to_xyz(WL, s[0], observer=observer), absolute[0])


def test_chromaticity_and_cct_agree_with_colour_science():
    # Blackbodies between 2000 and 10 000 K with a little smooth tint: near the locus, where
    # CCT means something.
    t = np.linspace(2000, 10000, 25)
    bb = np.array([colour.sd_blackbody(k, colour.SpectralShape(360, 830, 1)).values for k in t])
    s = bb / bb.max(axis=1, keepdims=True) * (1 + 0.05 * smooth_spectra(len(t), 2))
    xyz = cc.sd_to_xyz(WL, s, "emissive")
    xy = cc.xyz_to_xy(xyz)
    cct = cc.xyz_to_cct_duv(xyz)
    rob = cc.xyz_to_cct_duv(xyz, method="robertson1968")
    for i in range(len(s)):
        assert rel_dev(xy[i], colour.XYZ_to_xy(xyz[i])) < 1e-12
        uv = colour.UCS_to_uv(colour.XYZ_to_UCS(xyz[i]))
        ohno = colour.temperature.uv_to_CCT_Ohno2013(uv)
        robertson = colour.temperature.uv_to_CCT_Robertson1968(uv)
        # The tolerances of tests/colour_science.rs: 0.5 K and 5e-5 in Duv.
        assert abs(cct[i, 0] - ohno[0]) < 0.5 and abs(cct[i, 1] - ohno[1]) < 5e-5
        assert abs(rob[i, 0] - robertson[0]) < 0.5 and abs(rob[i, 1] - robertson[1]) < 5e-5
    # Any leading shape.
    assert cc.xyz_to_xy(xyz.reshape(5, 5, 3)).shape == (5, 5, 2)


def test_cri_agrees_with_colour_science():
    names = ["FL2", "FL7", "FL11", "A", "D65"]
    rows = []
    for name in names:
        w, v = cc.named_spectrum(name)
        rows.append(np.interp(WL, w, v, left=0, right=0))
    s = np.array(rows)
    c = cc.cri(WL, s)
    assert c["R"].shape == (len(names), 14)
    for i in range(len(names)):
        q = colour.colour_rendering_index(sd(s[i]), additional_data=True)
        # The tolerance of tests/colour_science.rs: 0.01 in Ra and in each Ri.
        assert abs(c["Ra"][i] - q.Q_a) < 0.01, names[i]
        ri = np.array([q.Q_as[k].Q_a for k in sorted(q.Q_as)])
        assert np.max(np.abs(c["R"][i] - ri)) < 0.01, names[i]


def test_tm30_agrees_with_colour_science():
    from colour.quality import colour_fidelity_index_ANSIIESTM3018

    t = np.array([2700.0, 4000.0, 6500.0])
    s = np.array([colour.sd_blackbody(k, colour.SpectralShape(360, 830, 1)).values for k in t])
    s = s * (1 + 0.3 * smooth_spectra(len(t), 3))
    r = cc.tm30(WL, s)
    for i in range(len(t)):
        tm = colour_fidelity_index_ANSIIESTM3018(sd(s[i]), additional_data=True)
        # The tolerances of tests/colour_health.rs: 1e-6 in Rf, Rg and the bins' Rf,hj.
        assert abs(r["Rf"][i] - tm.R_f) < 1e-6
        assert abs(r["Rg"][i] - tm.R_g) < 1e-6
        assert np.max(np.abs(r["Rf_bins"][i] - tm.R_fs)) < 1e-6


def test_alpha_opic_of_d65_meets_the_definition():
    w, v = cc.named_spectrum("D65")
    q = cc.alpha_opic(w, np.array([v, 2 * v]))
    # DER is relative to D65, so D65's is 1 in every channel, and its α-opic EDIs equal its
    # illuminance; all are linear in the spectrum.
    assert np.allclose(q["der"], 1.0, rtol=1e-12, atol=0)
    assert np.allclose(q["edi_lx"], q["illuminance_lx"][:, None], rtol=1e-12, atol=0)
    assert q["illuminance_lx"][1] == pytest.approx(2 * q["illuminance_lx"][0], rel=1e-14)
    assert np.allclose(q["equivalent_melanopic_lux"], q["edi_lx"][:, 4] / 0.9058, rtol=1e-12)


def test_bad_spectra_raise_candela_error():
    with pytest.raises(candela.CandelaError, match="values has 3 columns but wavelengths_nm has 4 wavelengths"):
        cc.sd_to_xyz([400, 500, 600, 700], np.ones((2, 3)))
    with pytest.raises(candela.CandelaError, match="spectrum 1: .*non-finite"):
        cc.sd_to_xyz([400, 500, 600], np.array([[1, 1, 1], [1, np.nan, 1]]))
    with pytest.raises(candela.CandelaError, match="observer"):
        cc.sd_to_xyz(WL, np.ones(WL.size), observer="1976")


def test_coarse_rows_are_resampled_as_colour_science_interpolates():
    """A 10 nm row gives the XYZ of colour-science's own interpolation of it to 1 nm (Sprague,
    its default for even steps), not that of straight lines between the samples."""
    coarse_wl = np.arange(360.0, 831.0, 10.0)
    rng = np.random.default_rng(7)
    mu, sigma = rng.uniform(450, 650), rng.uniform(20, 60)
    values = 0.05 + np.exp(-0.5 * ((coarse_wl - mu) / sigma) ** 2)
    fine = colour.SpectralDistribution(values, coarse_wl).copy().interpolate(colour.SpectralShape(360, 830, 1))
    got = cc.sd_to_xyz(coarse_wl, values, "absolute")
    want = cc.sd_to_xyz(WL, fine.values, "absolute")
    linear = cc.sd_to_xyz(WL, np.interp(WL, coarse_wl, values), "absolute")
    assert rel_dev(got, want) < 1e-12
    # The difference the test can see: straight lines are off by far more than the tolerance.
    assert rel_dev(linear, want) > 1e-6
