"""candela's colour library on numpy arrays (docs/colour.md).

Spectra are given as ``wavelengths_nm`` (W,) and ``values`` (N, W) or (W,): each row is
resampled to candela's 1 nm grid over 360–830 nm by linear interpolation (0 outside its
samples), as a spectrum file is, and handed to the same functions the renderer and
``candela spectrum`` use. A single spectrum (W,) gives results without the leading axis.
"""

from __future__ import annotations

from typing import Dict, Optional, Tuple

import numpy as np

from . import _candela

__all__ = [
    "sd_to_xyz",
    "xyz_to_xy",
    "xyz_to_cct_duv",
    "cri",
    "alpha_opic",
    "tm30",
    "named_spectrum",
    "ALPHA_OPIC",
]

ALPHA_OPIC = ("s-cone-opic", "m-cone-opic", "l-cone-opic", "rhodopic", "melanopic")
"""The order of the five α-opic columns (CIE S 026)."""


def _floats(x, name: str) -> np.ndarray:
    """``x`` as a float64 array, or TypeError / ValueError naming the argument."""
    if isinstance(x, (str, bytes)):
        raise TypeError(f"{name} must be an array of numbers, got {type(x).__name__}")
    try:
        a = np.asarray(x)
    except (TypeError, ValueError) as e:
        raise TypeError(f"{name} must be an array of numbers: {e}") from None
    if a.dtype.kind not in "biuf":
        raise TypeError(f"{name} must be an array of real numbers, got dtype {a.dtype}")
    return np.ascontiguousarray(a, dtype=np.float64)


def _text(v, name: str) -> str:
    if not isinstance(v, str):
        raise TypeError(f"{name} must be a str, got {type(v).__name__}")
    return v


def _spectra(wavelengths_nm, values) -> Tuple[np.ndarray, np.ndarray, bool]:
    w = _floats(wavelengths_nm, "wavelengths_nm")
    if w.ndim != 1:
        raise ValueError(f"wavelengths_nm must be a 1-D array (W,), got shape {w.shape}")
    v = _floats(values, "values")
    if v.ndim not in (1, 2):
        raise ValueError(f"values must be (W,) or (N, W), got shape {v.shape}")
    single = v.ndim == 1
    return w, np.ascontiguousarray(np.atleast_2d(v)), single


def _xyz(xyz) -> np.ndarray:
    a = _floats(xyz, "xyz")
    if a.ndim == 0 or a.shape[-1] != 3:
        raise ValueError(f"xyz must be an array of shape (..., 3), got shape {a.shape}")
    return a


def _squeeze(a, single: bool):
    if isinstance(a, dict):
        return {k: _squeeze(x, single) for k, x in a.items()}
    return a[0] if single else a


def sd_to_xyz(
    wavelengths_nm,
    values,
    kind: str = "absolute",
    illuminant: Optional[Tuple[np.ndarray, np.ndarray]] = None,
    observer: str = "1931",
    method: str = "integration",
) -> np.ndarray:
    """Tristimulus values XYZ of spectra, (N, 3).

    ``kind``: ``"absolute"`` — X = K_m Σ S(λ) x̄(λ) Δλ with K_m = 683 lm/W, so Y is luminance
    in cd/m² for a spectral radiance in W·m⁻²·sr⁻¹·nm⁻¹ (illuminance in lx for an irradiance
    in W·m⁻²·nm⁻¹); ``"emissive"`` — relative, Y = 100 for S ≡ 1 (colour-science's default for
    a light source); ``"relative"`` — object colours (reflectances) under ``illuminant``
    (wavelengths_nm, values), Y = 100 for the perfect diffuser.
    ``observer``: ``"1931"`` (2°) or ``"1964"`` (10°). ``method``: ``"integration"`` (the full
    360–830 nm sum; colour-science ``method="Integration"``) or ``"astm-e308"`` (360–780 nm;
    colour-science's default for 1 nm data).
    """
    w, v, single = _spectra(wavelengths_nm, values)
    kind, observer, method = _text(kind, "kind"), _text(observer, "observer"), _text(method, "method")
    ill = None
    if illuminant is not None:
        if isinstance(illuminant, (str, bytes)) or not hasattr(illuminant, "__len__") \
                or len(illuminant) != 2:
            raise TypeError("illuminant must be (wavelengths_nm, values)")
        ill = (_floats(illuminant[0], "illuminant[0]"), _floats(illuminant[1], "illuminant[1]"))
        if ill[0].ndim != 1 or ill[1].ndim != 1:
            raise ValueError("illuminant must be two 1-D arrays (wavelengths_nm, values)")
    return _squeeze(_candela.sd_to_xyz(w, v, kind, ill, observer, method), single)


def xyz_to_xy(xyz) -> np.ndarray:
    """CIE 1931 chromaticity coordinates (x, y) of XYZ (..., 3) → (..., 2)."""
    a = _xyz(xyz)
    r = _candela.xyz_to_xy_array(np.ascontiguousarray(a.reshape(-1, 3)))
    return r.reshape(a.shape[:-1] + (2,))


def xyz_to_cct_duv(xyz, method: str = "ohno2013") -> np.ndarray:
    """Correlated colour temperature (K) and Duv of XYZ (..., 3) → (..., 2), by Ohno (2013)
    (colour-science ``XYZ_to_CCT_Ohno2013``; within 0.5 K and 5e-5 Duv of it) or
    ``"robertson1968"``."""
    a = _xyz(xyz)
    r = _candela.xyz_to_cct_duv(np.ascontiguousarray(a.reshape(-1, 3)), _text(method, "method"))
    return r.reshape(a.shape[:-1] + (2,))


def cri(wavelengths_nm, values) -> Dict[str, np.ndarray]:
    """CIE 13.3-1995 colour rendering index of light sources: ``Ra`` (N,), ``R`` (N, 14) —
    R1 … R14 —, ``cct_K`` and ``duv`` (Robertson 1968) of the source."""
    w, v, single = _spectra(wavelengths_nm, values)
    return _squeeze(_candela.cri(w, v), single)


def alpha_opic(wavelengths_nm, values) -> Dict[str, np.ndarray]:
    """CIE S 026 α-opic quantities of spectral irradiances (W·m⁻²·nm⁻¹): ``irradiance_W_m2``
    (N, 5), ``illuminance_lx`` (N,), ``elr_W_per_lm`` (N, 5), ``der`` (N, 5), ``edi_lx`` (N, 5)
    and WELL's ``equivalent_melanopic_lux`` (N,); columns in :data:`ALPHA_OPIC` order. For a
    spectral radiance read W·m⁻²·sr⁻¹ for W·m⁻² and cd/m² for lx."""
    w, v, single = _spectra(wavelengths_nm, values)
    return _squeeze(_candela.alpha_opic(w, v), single)


def tm30(wavelengths_nm, values) -> Dict[str, np.ndarray]:
    """ANSI/IES TM-30-20 and CIE 224:2017 colour rendition of light sources: ``Rf``, ``Rg``,
    ``cct_K``, ``duv`` (N,) and per hue bin (N, 16) ``Rf_bins``, ``chroma_shift_percent``,
    ``hue_shift_rad``; NaN where a spectrum is outside the method's domain."""
    w, v, single = _spectra(wavelengths_nm, values)
    return _squeeze(_candela.tm30(w, v), single)


def named_spectrum(name: str) -> Tuple[np.ndarray, np.ndarray]:
    """A spectrum of candela's tables (``"D65"``, ``"A"``, ``"FL2"``, ``"LED-B3"``,
    ``"TCS01"``, …) at its own wavelengths: (wavelengths_nm, values)."""
    return _candela.named_spectrum(_text(name, "name"))
