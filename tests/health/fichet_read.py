"""Read a spectral OpenEXR with colour-science's Fichet et al. (2021) reader and integrate
each pixel's spectrum with the CIE 1931 2° ȳ at the band centres: prints JSON with the
wavelengths (nm), the emissive units attribute, the image size and, per pixel (row-major),
Y = 683 Σ S(λ_k) ȳ(λ_k) Δλ (cd/m² for spectral radiance in W·m⁻²·sr⁻¹·nm⁻¹) and the spectrum of
pixel 0."""
import json
import sys
import warnings

warnings.filterwarnings("ignore")
import colour  # noqa: E402
import numpy as np  # noqa: E402

components, spec = colour.io.read_spectral_image_Fichet2021(sys.argv[1], additional_data=True)
wavelengths, values = components["S0"]
order = np.argsort(wavelengths)
wavelengths, values = wavelengths[order], values[:, :, order]
cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
ybar = np.interp(wavelengths, cmfs.wavelengths, cmfs.values[:, 1])
step = float(wavelengths[1] - wavelengths[0])
y = 683.0 * np.einsum("hwk,k->hw", values.astype(np.float64), ybar) * step
attributes = {a.name: str(a.value) for a in spec.attributes}
print(
    json.dumps(
        {
            "wavelengths": wavelengths.tolist(),
            "is_emissive": bool(spec.is_emissive),
            "emissive_units": attributes.get("emissiveUnits"),
            "layout_version": attributes.get("spectralLayoutVersion"),
            "height": int(values.shape[0]),
            "width": int(values.shape[1]),
            "y": y.ravel().tolist(),
            "pixel0": values[0, 0, :].astype(np.float64).tolist(),
        }
    )
)
