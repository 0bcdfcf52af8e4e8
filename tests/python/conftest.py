"""Shared fixtures of the Python package's tests: the test scene, its dict form and the
`candela` command line (built by `cargo test`; CANDELA_BIN overrides)."""

import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DATA = Path(__file__).resolve().parent / "data"


@pytest.fixture
def scene_path() -> Path:
    return DATA / "small-room.ron"


def quad(origin, u, v):
    return {"Quad": {"origin": origin, "edge_u": u, "edge_v": v}}


@pytest.fixture
def scene_dict() -> dict:
    """data/small-room.ron as a dict (serde's JSON shape of the scene format)."""
    return {
        "camera": {
            "position": [3.6, 1.6, 4.6],
            "look_at": [1.6, 0.8, 1.8],
            "vfov_deg": 60.0,
            "resolution": [48, 36],
        },
        "render": {"spp": 8, "seed": 3, "filter": {"Gaussian": {"sigma": 0.5, "radius": 1.5}}},
        "materials": {
            "wall": {"Diffuse": {"reflectance": {"Constant": 0.7}}},
            "floor": {"Diffuse": {"reflectance": {"Rgb": [0.30, 0.24, 0.18]}}},
            "desk": {"Diffuse": {"reflectance": {"Rgb": [0.45, 0.25, 0.12]}}},
        },
        "objects": [
            {"name": "floor", "material": "floor", "shape": quad([0, 0, 0], [0, 0, 5], [4, 0, 0])},
            {"name": "ceiling", "material": "wall", "shape": quad([0, 3, 0], [4, 0, 0], [0, 0, 5])},
            {"name": "wall x=0", "material": "wall", "shape": quad([0, 0, 0], [0, 3, 0], [0, 0, 5])},
            {"name": "wall z=0", "material": "wall", "shape": quad([0, 0, 0], [4, 0, 0], [0, 3, 0])},
            {
                "name": "desk top",
                "material": "desk",
                "shape": quad([0.8, 0.75, 1.4], [0, 0, 0.8], [1.6, 0, 0]),
            },
        ],
        "meters": [
            {"Illuminance": {"name": "desk centre", "position": [1.6, 0.751, 1.8], "normal": [0, 1, 0]}},
            {
                "Luminance": {
                    "name": "wall",
                    "position": [1.6, 1.2, 3.5],
                    "direction": [0, 0, -1],
                    "half_angle_deg": 1.0,
                }
            },
        ],
        "grids": [
            {
                "name": "work plane",
                "origin": [0, 0.8, 0],
                "edge_u": [4, 0, 0],
                "edge_v": [0, 0, 5],
                "nx": 4,
                "ny": 5,
            }
        ],
        "measure": {"samples": 256},
        "lights": [
            {
                "Spot": {
                    "position": [1.6, 2.99, 1.8],
                    "look_at": [1.6, 0.0, 1.8],
                    "inner_deg": 20.0,
                    "outer_deg": 35.0,
                    "spectrum": {"Blackbody": 3000.0},
                    "amount": {"Intensity": 2000.0},
                }
            }
        ],
    }


@pytest.fixture(scope="session")
def candela_bin() -> Path:
    """The command-line binary of this tree (the one `cargo test` builds)."""
    env = os.environ.get("CANDELA_BIN")
    if env:
        return Path(env)
    path = ROOT / "target" / "debug" / "candela"
    if not path.exists():
        subprocess.run(["cargo", "build", "--profile", "test", "--bin", "candela"], cwd=ROOT, check=True)
    return path
