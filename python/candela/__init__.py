"""candela — a spectral path tracer whose output is measured light, from Python.

Every image is a calibrated photometric quantity: ``Y`` is luminance in cd/m², ``E``
illuminance in lx. :func:`render` runs exactly the job of ``candela render`` (the same library
call and settings), so for the same scene and seed it writes the same images, bit for bit, and
returns the image as numpy arrays with the report as a dict. See docs/python.md.

Errors candela reports (a bad scene, a bad option, a damaged file) raise :class:`CandelaError`
whose message is candela's own: it names the file, the line:column, the field path or the
argument. A file that cannot be read or written raises :class:`FileError`, which is both a
CandelaError and an OSError (with ``errno`` when the system refused).
"""

from __future__ import annotations

import glob
import json
import operator
import os
import stat
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Dict, List, Mapping, Optional, Union

import numpy as np

from . import _candela
from ._candela import Cancelled, CandelaError, FileError, __version__
from . import colour

__all__ = [
    "CandelaError",
    "Cancelled",
    "FileError",
    "Scene",
    "RenderResult",
    "render",
    "merge",
    "MergeResult",
    "read_exr",
    "read_state",
    "colour",
    "__version__",
]

Progress = Callable[[int, int, float], Optional[bool]]
"""``progress(samples_done, samples_total, elapsed_s)``: called when the render starts and
after every pass; returning ``False`` (exactly) cancels the render."""


def _jsonable(o: Any) -> Any:
    """numpy scalars and arrays in a scene dict, as plain numbers and lists."""
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, np.generic):
        return o.item()
    raise TypeError(f"a scene dict holds a {type(o).__name__}, which has no RON form")


MAX_NAME_BYTES = 210
"""Longest scene name in UTF-8 bytes: NAME.illuminance.png, the longest output name besides a
grid's, with the temporary file written beside it (29 bytes more) fits the 255 bytes of a file
name on most file systems."""

_MARK = "\n// candela: written by the Python module for a scene from text or a dict; a render of\n// another scene of this name into this directory may replace it.\n"
"""The last lines of a scene file the module writes: such a file may be replaced, no other."""


MAX_TEXT_BYTES = 256 << 20
"""Largest scene text in bytes: what a render reads of a scene file (``candela::limits``)."""


def _check_text(text: Any) -> str:
    """Scene text that a render can read back from its file, or TypeError / CandelaError."""
    if not isinstance(text, str):
        raise TypeError(f"text must be a str, got {type(text).__name__}")
    try:
        n = len(text.encode("utf-8"))
    except UnicodeEncodeError:
        raise CandelaError("text must be valid Unicode (no lone surrogates)") from None
    if n + len(_MARK) > MAX_TEXT_BYTES:
        raise CandelaError(f"text is {n} bytes, more than the limit of {MAX_TEXT_BYTES} bytes "
                           "of a scene file")
    return text


def _check_name(name: Any) -> str:
    """``name`` as a plain file-name stem, or TypeError / CandelaError naming it."""
    if not isinstance(name, str):
        raise TypeError(f"name must be a str, got {type(name).__name__}")
    shown = repr(name) if len(name) <= 60 else repr(name[:60]) + "…"
    if name in ("", ".", ".."):
        raise CandelaError(f"name must be a file-name stem (outputs are NAME.exr, …), got {shown}")
    bad = [c for c in name if c in "/\\" or c in (os.sep, os.altsep or "/")
           or ord(c) < 0x20 or 0x7F <= ord(c) < 0xA0]
    if bad:
        raise CandelaError(
            f"name must be a file-name stem without path separators or control characters, got {shown}")
    try:
        n = len(name.encode("utf-8"))
    except UnicodeEncodeError:
        raise CandelaError(f"name must be valid Unicode text (no lone surrogates), got {shown}") from None
    if n > MAX_NAME_BYTES:
        raise CandelaError(
            f"name is {n} bytes long in UTF-8; at most {MAX_NAME_BYTES} leave room for the outputs' "
            f"suffixes and temporary files within a file name, got {shown}")
    return name


class Scene:
    """A scene: a RON file, RON text or a Python dict (checked for syntax, types and unknown
    fields on creation; values are checked when it renders, or by :meth:`check`).

    A dict has the shape serde gives the scene format in JSON: a struct is a dict of its
    fields, an enum variant a one-key dict ``{"Variant": content}`` (``{"Blackbody": 3000.0}``,
    ``{"Diffuse": {"reflectance": {"Constant": 0.7}}}``) or, if it has no content, the string
    ``"Variant"``; tuples and vectors are lists. Field names and units are those of
    docs/scene-format.md.

    A scene from text or a dict is written to the output directory as ``NAME.ron`` before it
    renders, so files it refers to (meshes, spectra, luminaires) need absolute paths. ``name``
    is a file-name stem (no path separators, no control characters, at most
    :data:`MAX_NAME_BYTES` bytes). ``NAME.ron`` never replaces a file the module did not
    write: an existing one is used if it holds the same scene, replaced if the module wrote it
    (and no render state of that name would be left behind, unless ``overwrite=True``), and
    refused otherwise.
    """

    def __init__(self, *, path: Optional[Path] = None, text: Optional[str] = None,
                 name: str = "scene") -> None:
        if (path is None) == (text is None):
            raise TypeError("Scene needs exactly one of path= and text= (or use from_file, "
                            "from_ron, from_dict)")
        self.path = None if path is None else Path(_fspath(path, "path"))
        self.text = None if text is None else _check_text(text)
        if not isinstance(name, str):
            raise TypeError(f"name must be a str, got {type(name).__name__}")
        # A scene file's outputs are named after it by the render, which checks them; only a
        # scene from text is written under this name.
        self.name = name if text is None else _check_name(name)

    @classmethod
    def from_file(cls, path: Union[str, os.PathLike]) -> "Scene":
        """A scene file (RON); raises CandelaError naming the file and line:column, FileError
        if it cannot be read."""
        p = Path(_fspath(path, "path"))
        _candela.read_scene_file(str(p))
        return cls(path=p, name=p.stem)

    @classmethod
    def from_ron(cls, text: str, name: str = "scene") -> "Scene":
        """RON text of a scene; ``name`` names the outputs (``NAME.exr``, …) and the scene
        file written beside them (``NAME.ron``)."""
        name = _check_name(name)
        _candela.check_scene_text(_check_text(text), f"{name}.ron")
        return cls(text=text, name=name)

    @classmethod
    def from_dict(cls, scene: Mapping[str, Any], name: str = "scene") -> "Scene":
        """A scene as a dict (see the class doc); raises CandelaError naming the field path."""
        name = _check_name(name)
        if not isinstance(scene, Mapping):
            raise TypeError(f"scene must be a dict, got {type(scene).__name__}")
        try:
            dumped = json.dumps(scene, default=_jsonable)
        except RecursionError:
            raise CandelaError("scene dict: nested too deeply to be a scene") from None
        except ValueError as e:  # a circular reference
            raise CandelaError(f"scene dict: {e}") from None
        except TypeError as e:
            raise TypeError(f"scene dict: {e}") from None
        if len(dumped) > MAX_TEXT_BYTES:
            raise CandelaError(f"scene dict: {len(dumped)} bytes as JSON, more than the limit of "
                               f"{MAX_TEXT_BYTES} bytes of a scene file")
        text = _candela.scene_dict_to_ron(dumped)
        return cls(text=_check_text(text), name=name)

    @property
    def ron(self) -> str:
        """The scene's RON text."""
        if self.text is not None:
            return self.text
        assert self.path is not None
        return _candela.read_scene_file(str(self.path))

    def check(self) -> tuple:
        """Builds the scene as a render would (every value checked, referenced files read);
        returns the image size ``(width, height)`` in pixels."""
        if self.path is not None:
            return _candela.check_scene_file(str(self.path))
        with tempfile.TemporaryDirectory(prefix="candela-") as d:
            return _candela.check_scene_file(self._write(Path(d), overwrite=False))

    def _write(self, directory: Path, overwrite: bool) -> str:
        """Writes the scene as DIRECTORY/NAME.ron without ever replacing a file the module did
        not write (see the class doc); returns its path."""
        target = directory / f"{self.name}.ron"
        data = (self.ron + _MARK).encode("utf-8")
        try:
            st = os.lstat(target)
        except FileNotFoundError:
            st = None
        if st is not None:
            if not stat.S_ISREG(st.st_mode):
                raise CandelaError(
                    f"name={self.name!r}: {target} exists and is not a regular file (a directory, "
                    "link or special file); choose another name or out")
            if st.st_size == len(data) and _read_prefix(target, len(data) + 1) == data:
                return str(target)  # the same scene, written earlier
            tail = _read_tail(target, st.st_size, len(_MARK.encode()))
            if tail != _MARK.encode():
                raise CandelaError(
                    f"name={self.name!r}: {target} exists and was not written by candela for a "
                    "scene; a scene from text or a dict is written as NAME.ron beside its outputs "
                    "and never replaces another file: choose another name or out")
            states = [p for p in glob.glob(os.path.join(glob.escape(str(directory)),
                                                        glob.escape(self.name) + ".*state"))
                      if p == f"{directory / self.name}.state"
                      or p.startswith(f"{directory / self.name}.shard-")]
            if states and not overwrite:
                raise CandelaError(
                    f"name={self.name!r}: {target} holds another scene, rendered into "
                    f"{os.path.basename(states[0])}: continue that render with the same scene, or "
                    "replace both with overwrite=True (or choose another name or out)")
        try:
            return self._write_new(directory, target, data, replace=st is not None)
        except FileError:
            raise
        except OSError as e:
            raise FileError(e.errno, f"cannot write the scene file {target}: {e.strerror or e}") from None

    def _write_new(self, directory: Path, target: Path, data: bytes, replace: bool) -> str:
        fd, tmp = tempfile.mkstemp(prefix=f".{self.name}.", suffix=".tmp", dir=directory)
        try:
            with os.fdopen(fd, "wb") as f:
                f.write(data)
                f.flush()
                os.fsync(f.fileno())
            if not replace:
                try:
                    # A link never replaces: a file made meanwhile by another process stays.
                    os.link(tmp, target)
                except FileExistsError:
                    if _read_prefix(target, len(data) + 1) == data:
                        return str(target)  # written by a render of the same scene meanwhile
                    raise CandelaError(
                        f"name={self.name!r}: {target} was created by someone else meanwhile; "
                        "render again") from None
                except OSError:
                    # A file system without hard links: create the file, never replacing one.
                    fd = os.open(target, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
                    try:
                        with os.fdopen(fd, "wb") as f:
                            f.write(data)
                    except OSError:
                        os.unlink(target)
                        raise
            else:
                os.replace(tmp, target)
        finally:
            try:
                os.unlink(tmp)
            except FileNotFoundError:
                pass
        return str(target)

    def __repr__(self) -> str:
        return f"Scene(path={str(self.path)!r})" if self.path else f"Scene(name={self.name!r}, text=…)"


def _read_prefix(path: Path, n: int) -> bytes:
    """At most n bytes from the start of a regular file (never blocking on a FIFO put there
    meanwhile)."""
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOFOLLOW", 0))
    try:
        return os.read(fd, n)
    finally:
        os.close(fd)


def _read_tail(path: Path, size: int, n: int) -> bytes:
    """The last n bytes of a regular file of `size` bytes."""
    if size < n:
        return b""
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOFOLLOW", 0))
    try:
        os.lseek(fd, size - n, os.SEEK_SET)
        return os.read(fd, n)
    finally:
        os.close(fd)


def _fspath(p: Any, name: str) -> str:
    """A path argument as str, or TypeError naming it."""
    try:
        f = os.fspath(p)
    except TypeError:
        raise TypeError(f"{name} must be a path (str or os.PathLike), got {type(p).__name__}") from None
    if isinstance(f, bytes):
        f = os.fsdecode(f)
    return f


def _scene(scene: Union["Scene", str, os.PathLike, Mapping[str, Any]]) -> Scene:
    if isinstance(scene, Scene):
        return scene
    if isinstance(scene, Mapping):
        return Scene.from_dict(scene)
    return Scene.from_file(_fspath(scene, "scene"))


@dataclass
class RenderResult:
    """A finished render. Images are float32 arrays of shape (height, width), row 0 at the top,
    exactly the EXR's channels."""

    X: np.ndarray
    """CIE 1931 X, same scale as Y."""
    Y: np.ndarray
    """Luminance, cd/m² (absolute CIE 1931 Y)."""
    Z: np.ndarray
    """CIE 1931 Z, same scale as Y."""
    Y_stderr: np.ndarray
    """Standard error of each pixel's Y, cd/m² (0: unknown, fewer than 2 samples)."""
    E: Optional[np.ndarray]
    """Illuminance on the surface seen through each pixel, lx; -1 where E_mask is 0 (with
    ``illuminance=True``, else None)."""
    E_stderr: Optional[np.ndarray]
    """Standard error of E, lx."""
    E_mask: Optional[np.ndarray]
    """Fraction of the pixel's samples that saw a receiving surface (E defined where > 0)."""
    channels: Dict[str, np.ndarray]
    """Every EXR channel by name (``X``, ``Y``, ``Z``, ``stderr.Y``, ``E``, ``stderr.E``,
    ``mask.E``; with ``alpha_opic`` ``melanopic.EDL`` and ``stderr.melanopic.EDL`` in cd/m²,
    and with illuminance too ``melanopic.EDI``, ``stderr.melanopic.EDI`` in lx; with
    ``mesopic`` ``scotopic.L``, ``mesopic.L``, ``stderr.mesopic.L`` in cd/m² and ``mesopic.m``)."""
    report: Dict[str, Any]
    """NAME.report.json as a dict (schema: docs/report-json.md)."""
    meters: Dict[str, Dict[str, Any]]
    """The report's meters by name: ``value``, ``stderr``, ``ci95_low``, ``ci95_high`` in
    ``unit`` (lx or cd/m² in SI units), …"""
    grids: Dict[str, Dict[str, Any]]
    """The report's grids by name, with ``values`` and ``stderr`` as (ny, nx) float64 arrays
    in ``unit`` (lx in SI units); row j, column i is the point at
    origin + (i+½)/nx·edge_u + (j+½)/ny·edge_v."""
    exr_path: Path
    png_path: Path
    report_path: Path
    outputs: List[str]
    """Every file written at the end."""
    samples_per_pixel: float
    elapsed_s: float
    """Render time of this run, s (the meters and grids excluded)."""
    samples_per_second: float
    warnings: List[str] = field(default_factory=list)
    """Checkpoints that could not be written, and paths cut short at a finite max depth."""


def render(
    scene: Union[Scene, str, os.PathLike, Mapping[str, Any]],
    *,
    out: Union[str, os.PathLike, None] = None,
    spp: Optional[int] = None,
    seed: Optional[int] = None,
    max_depth: Optional[int] = None,
    threads: Optional[int] = None,
    illuminance: bool = False,
    caustics: Optional[str] = None,
    exposure_ev: Optional[float] = None,
    units: str = "si",
    target_error: Optional[float] = None,
    target_fraction: float = 1.0,
    target_floor_cd_m2: Optional[float] = None,
    max_spp: Optional[int] = None,
    max_time_s: Optional[float] = None,
    checkpoint_interval_s: Optional[float] = None,
    resume: bool = False,
    overwrite: bool = False,
    save_state: bool = False,
    falsecolour: bool = False,
    shard: Union[str, tuple, None] = None,
    alpha_opic: bool = False,
    mesopic: bool = False,
    spectral_bands: int = 0,
    progress: Optional[Progress] = None,
    cancel: Any = None,
) -> RenderResult:
    """Render a scene as ``candela render`` does and return the image and report.

    ``scene`` is a :class:`Scene`, a scene file path or a scene dict. ``out`` is what
    ``--out`` is (an existing directory, or ``NAME``/``NAME.exr``); None: a new temporary
    directory, kept (the result's paths name it). A scene from text or a dict needs a
    directory (or None). The other arguments are the command's options: ``spp`` (samples per
    pixel), ``seed``, ``max_depth``, ``threads`` (the image does not depend on it),
    ``illuminance`` (E in lx per pixel), ``caustics`` (``"light-tracing"`` or
    ``"path-tracing"``), ``exposure_ev`` (PNG only), ``units`` (``"si"`` or ``"imperial"``,
    for the report), ``target_error`` (a fraction, 0.01 = 1 %, with ``target_fraction`` and
    ``target_floor_cd_m2``), ``max_spp``, ``max_time_s`` and ``checkpoint_interval_s``
    (seconds; no checkpoints by default), ``resume``, ``overwrite``, ``save_state`` and
    ``falsecolour``. ``shard`` renders one shard of a render split N ways (``--shard``): ``(I,
    N)`` or ``"I/N"`` (0-based), or ``"auto"`` / ``"auto/N"`` to take it from a Slurm, AWS
    Batch or Kubernetes array job's variables; :func:`merge` combines the shards.
    ``alpha_opic`` keeps the melanopic EDL per pixel (and EDI with ``illuminance``),
    ``mesopic`` the CIE 191 mesopic luminance, ``spectral_bands`` N spectral bands written to
    NAME.spectral.exr (``--alpha-opic``, ``--mesopic``, ``--spectral-bands``; the first two
    come back in ``channels``).

    ``progress(samples_done, samples_total, elapsed_s)`` is called at the start and after
    every pass; returning ``False`` cancels. ``cancel`` is anything with ``is_set()`` (a
    ``threading.Event``) checked every 50 ms. A cancelled render raises :class:`Cancelled`
    at the end of the pass in progress, saying what was written (a checkpoint, as Ctrl-C
    leaves from the command line); Ctrl-C stops it the same way and raises KeyboardInterrupt.
    """
    s = _scene(scene)
    if out is not None:
        out = _fspath(out, "out")
    if not isinstance(overwrite, bool):
        raise TypeError(f"overwrite must be a bool, got {type(overwrite).__name__}")
    if s.path is not None:
        scene_path = str(s.path)
        out_arg = out
    else:
        directory = Path(out) if out is not None else Path(tempfile.mkdtemp(prefix="candela-"))
        if not directory.is_dir():
            raise CandelaError(
                f"out {directory} is not an existing directory: a scene from text or a dict "
                "is written there as NAME.ron, next to its outputs"
            )
        scene_path = s._write(directory, overwrite=overwrite)
        out_arg = directory
    if out_arg is None:
        out_arg = tempfile.mkdtemp(prefix="candela-")
    r = _candela.render(
        scene_path,
        os.fspath(out_arg),
        spp=spp,
        seed=seed,
        max_depth=max_depth,
        threads=threads,
        illuminance=illuminance,
        caustics=caustics,
        exposure_ev=exposure_ev,
        units=units,
        target_error=target_error,
        target_fraction=target_fraction,
        target_floor_cd_m2=target_floor_cd_m2,
        max_spp=max_spp,
        max_time_s=max_time_s,
        checkpoint_interval_s=checkpoint_interval_s,
        resume=resume,
        overwrite=overwrite,
        save_state=save_state,
        falsecolour=falsecolour,
        shard=_shard_spec(shard),
        alpha_opic=alpha_opic,
        mesopic=mesopic,
        spectral_bands=spectral_bands,
        progress=progress,
        cancel=cancel,
    )
    ch = r["channels"]
    report = json.loads(r["report_json"])
    grids = {}
    for g in report.get("grids", []):
        g = dict(g)
        for k in ("values", "stderr"):
            g[k] = np.asarray(g[k], dtype=np.float64).reshape(g["ny"], g["nx"])
        grids[g["name"]] = g
    warnings = list(r["warnings"])
    if r["truncation"]:
        warnings.append(r["truncation"])
    return RenderResult(
        X=ch["X"],
        Y=ch["Y"],
        Z=ch["Z"],
        Y_stderr=ch["stderr.Y"],
        E=ch.get("E"),
        E_stderr=ch.get("stderr.E"),
        E_mask=ch.get("mask.E"),
        channels=dict(ch),
        report=report,
        meters={m["name"]: m for m in report.get("meters", [])},
        grids=grids,
        exr_path=Path(r["exr_path"]),
        png_path=Path(r["png_path"]),
        report_path=Path(r["report_path"]),
        outputs=list(r["outputs"]),
        samples_per_pixel=r["samples_per_pixel"],
        elapsed_s=r["elapsed_s"],
        samples_per_second=r["samples_per_second"],
        warnings=warnings,
    )


def _shard_spec(shard: Union[str, tuple, None]) -> Optional[str]:
    if shard is None or isinstance(shard, str):
        return shard
    try:
        index, count = shard
        if isinstance(index, bool) or isinstance(count, bool):
            raise TypeError
        return f"{operator.index(index)}/{operator.index(count)}"
    except (TypeError, ValueError):
        raise TypeError(f"shard must be (index, count) of integers or \"I/N\", got {shard!r:.80}") from None


@dataclass
class MergeResult:
    """What :func:`merge` wrote, and the merged image (float32 arrays, exactly OUT.exr)."""

    channels: Dict[str, np.ndarray]
    """OUT.exr's channels by name (``X``, ``Y``, ``Z``, ``stderr.Y`` in cd/m², …)."""
    exr_path: Path
    png_path: Path
    state_path: Path
    """The merged state (not written by a partial merge of shards)."""
    hdr_path: Optional[Path]
    """OUT.hdr, when the inputs' renders wrote NAME.hdr."""
    report_path: Optional[Path]
    """OUT.report.json (shards only), with the merged meters and grids."""
    report: Optional[Dict[str, Any]]
    renders: int
    """Number of states merged."""
    seeds: List[int]
    samples_per_pixel: float
    shards: Optional[Dict[str, Any]]
    """For shards: ``count``, ``spp_per_shard``, ``merged``, ``missing``, ``unfinished``,
    ``partial``; None for a merge of independent renders."""

    @property
    def Y(self) -> np.ndarray:
        """Luminance, cd/m²."""
        return self.channels["Y"]


def merge(
    states: List[Union[str, os.PathLike]],
    out: Union[str, os.PathLike],
    *,
    exposure_ev: Optional[float] = None,
    partial: bool = False,
) -> MergeResult:
    """Merge render states as ``candela merge`` does: independent renders of one scene
    (different seeds), or the shards of one render in any order (the same bits whatever the
    order). ``out`` names OUT (writes OUT.exr, OUT.png, OUT.state, and OUT.report.json for
    shards) or an existing directory (DIR/merged.*). ``partial`` merges the shards present
    even if some are missing or unfinished; without it such a merge raises
    :class:`CandelaError` naming them."""
    if isinstance(states, (str, bytes, os.PathLike)) or not hasattr(states, "__iter__"):
        raise TypeError(f"states must be a list of paths, got {type(states).__name__}")
    r = _candela.merge(
        [_fspath(p, "states[]") for p in states], _fspath(out, "out"),
        exposure_ev=exposure_ev, partial=partial,
    )
    path = lambda p: None if p is None else Path(p)  # noqa: E731
    return MergeResult(
        channels=dict(r["channels"]),
        exr_path=Path(r["exr_path"]),
        png_path=Path(r["png_path"]),
        state_path=Path(r["state_path"]),
        hdr_path=path(r["hdr_path"]),
        report_path=path(r["report_path"]),
        report=None if r["report_json"] is None else json.loads(r["report_json"]),
        renders=r["renders"],
        seeds=list(r["seeds"]),
        samples_per_pixel=r["samples_per_pixel"],
        shards=r["shards"],
    )


def read_exr(path: Union[str, os.PathLike]) -> Dict[str, Any]:
    """An EXR file: ``width``, ``height``, ``channels`` (name → float32 array of shape
    (height, width); for a candela render ``X``, ``Y``, ``Z``, ``stderr.Y`` in cd/m² and, with
    illuminance, ``E``, ``stderr.E`` in lx and ``mask.E``) and ``attributes`` (name → text:
    ``units``, ``scene``, ``spp``, ``projection``, …)."""
    return _candela.read_exr(_fspath(path, "path"))


def read_state(path: Union[str, os.PathLike]) -> Dict[str, Any]:
    """A render state (NAME.state; checksum and values checked as for ``--resume``): ``scene``,
    ``seed``, ``merged_seeds``, ``max_depth`` (None: unlimited), ``illuminance``, ``width``,
    ``height``, ``adaptive``, ``total_samples``, ``samples_per_pixel``, ``shard`` ((index,
    count, spp) or None), ``pixel_batches`` (independent sample batches per pixel), and
    ``channels``: the estimate it holds, as its EXR would have it."""
    return _candela.read_state(_fspath(path, "path"))
