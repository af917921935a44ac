"""xbandsim: a physics-based X-band marine radar simulator (Rust core, NumPy arrays out).

>>> import xbandsim
>>> sim = xbandsim.Simulation("scenes/paper.toml")
>>> frame = sim.render(seed=0)
>>> frame.polar_db.shape, frame.ppi_gray.shape, len(frame.objects)
((360, 668), (512, 512), 5)

The Rust core does the work (with the GIL released); this package converts Python values to
scene settings and the results to NumPy arrays and dicts. docs/python.md in the repository
describes the API; docs/formats.md the scene fields and the truth labels.
"""

import json
import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Mapping, Optional, Union

import numpy as np

from . import _args, _xbandsim
from . import data, dataset

try:  # The Gymnasium environments, when Gymnasium is installed (pip install xbandsim[gym]).
    import gymnasium as _gymnasium  # noqa: F401
except ImportError:  # pragma: no cover - exercised where gymnasium is absent
    pass
else:
    from . import envs

    envs.register_envs()
from .errors import (
    ArgumentTypeError,
    DatasetMismatchError,
    DatasetSpecError,
    EncodeError,
    IncompleteDatasetWarning,
    InvalidArgumentError,
    InvalidFieldError,
    MeshError,
    MissingFieldError,
    SceneSyntaxError,
    XbandsimError,
    XbandsimIOError,
)

__version__: str = _xbandsim.version()

PathLike = Union[str, "os.PathLike[str]"]


class Scene:
    """A scene description: radar, environment, objects, display (docs/formats.md).

    Immutable: :meth:`with_settings` returns a changed copy. Build one with
    :meth:`from_file`, :meth:`from_toml` or :meth:`from_dict`.
    """

    def __init__(self, spec: "_xbandsim.SceneSpec") -> None:
        self._spec = spec

    @classmethod
    def from_file(cls, path: PathLike) -> "Scene":
        """Reads a scene TOML file (mesh files are found relative to its folder)."""
        return cls(_xbandsim.SceneSpec.read(_args.path("path", path)))

    @classmethod
    def from_toml(cls, text: str, name: str = "<string>", base_dir: PathLike = ".") -> "Scene":
        """Parses scene TOML text; ``name`` names it in error messages."""
        return cls(
            _xbandsim.SceneSpec.from_toml(
                _args.text("text", text), _args.text("name", name), _args.path("base_dir", base_dir)
            )
        )

    @classmethod
    def from_dict(
        cls, scene: Mapping[str, Any], name: str = "<dict>", base_dir: PathLike = "."
    ) -> "Scene":
        """A scene from nested dicts and lists with the TOML file's layout, e.g.
        ``{"radar": {"spokes": 360}, "object": [{"name": "buoy", "shape": "point", ...}]}``.
        NumPy scalars and arrays are taken as their values; NaN and infinity are refused
        (``InvalidFieldError`` naming the field), as ``with_settings`` does."""
        name = _args.text("name", name)
        plain = _args.scene_value(_args.mapping("scene", scene), name, "")
        return cls(
            _xbandsim.SceneSpec.from_json(json.dumps(plain), name, _args.path("base_dir", base_dir))
        )

    def with_settings(self, settings: Mapping[str, Any]) -> "Scene":
        """A copy with fields set by dotted path, in order: ``{"radar.pulse_width_us": 0.5,
        "environment.sea_state": 4, "object[0].yaw_deg": 30}`` (the CLI's ``--set``). NumPy
        scalars and arrays are taken as their values; NaN and infinity are refused
        (``InvalidFieldError`` naming the field), as ``from_dict`` does."""
        pairs = []
        for k, v in _args.mapping("settings", settings).items():
            field = _args.text("settings key", k)
            pairs.append((field, json.dumps(_args.scene_value(v, "settings", field))))
        return Scene(self._spec.with_overrides(pairs))

    @property
    def origin(self) -> str:
        """The file path or name the scene came from."""
        return self._spec.origin

    def simulation(self) -> "Simulation":
        """Builds and checks the scene (raises on invalid fields)."""
        return Simulation(self)

    def __repr__(self) -> str:
        return f"Scene({self.origin!r})"


@dataclass(frozen=True)
class Frame:
    """One antenna revolution (docs/formats.md, "Outputs").

    Arrays are NumPy arrays owned by this object (moved from Rust, not copied).
    """

    polar_db: np.ndarray
    """Power over the mean noise, dB: float32 (spokes, range bins); spoke 0 at north."""
    ppi_db: np.ndarray
    """The PPI in dB: float32 (size, size), NaN outside the display circle."""
    ppi_gray: Optional[np.ndarray]
    """ppi_gray.png's pixels: uint8 (size, size); None with ``images=False``."""
    ppi_rgb: Optional[np.ndarray]
    """ppi.png's pixels (colour map, range rings): uint8 (size, size, 3)."""
    truth: Dict[str, Any]
    """truth.json as a dict: the frame header and one entry per object (``objects``)."""
    doppler_cube_db: Optional[np.ndarray] = None
    """Range-Doppler cube, dB: float32 (spokes, Doppler bins, range bins) (pulse mode)."""
    iq: Optional[np.ndarray] = None
    """Raw received I/Q: complex64 (pulses, samples), noise-rms units."""
    iq_pulses: Optional[Dict[str, np.ndarray]] = field(default=None)
    """Per pulse of ``iq``: ``time_s``, ``azimuth_deg``, ``spoke``."""
    video: Optional[np.ndarray] = None
    """The receiver's video levels: uint8 (video spokes, video samples), scenes with a
    ``[receiver]`` table (docs/formats.md, "video.npy")."""
    land_mask: Optional[np.ndarray] = None
    """1 where the polar cell shows land: uint8 (spokes, range bins), scenes whose radar
    sees land (docs/formats.md, "land_mask.npy")."""
    land_polygon: Optional[np.ndarray] = None
    """The land polygon each land cell shows (``truth["land"]["polygons"]``), −1 elsewhere:
    int32 (spokes, range bins)."""
    structure_mask: Optional[np.ndarray] = None
    """The object id of the structure whose footprint each polar cell shows
    (``truth["land"]["structures"]``), −1 elsewhere: int32 (spokes, range bins), scenes with
    ``[[structure]]`` tables (docs/formats.md, "structure_mask.npy")."""

    @property
    def objects(self) -> List[Dict[str, Any]]:
        """Per-object labels: position, echo box, visibility and its reason, SNR, ..."""
        return self.truth["objects"]


class Simulation:
    """A built, checked scene that renders frames.

    ``Simulation(path_or_scene)``. The scattering trace of a static scene is cached: later
    frames of the same scene reuse it.
    """

    def __init__(self, scene: Union[Scene, PathLike]) -> None:
        if not isinstance(scene, Scene):
            scene = Scene.from_file(scene)
        self.scene = scene
        self._sim = scene._spec.build()

    @property
    def polar_shape(self) -> tuple:
        """(spokes, range bins) of ``polar_db``."""
        spokes, bins, _, _ = self._sim.shape
        return (spokes, bins)

    @property
    def range_bin_m(self) -> float:
        """Range of one polar bin, m."""
        return self._sim.shape[2]

    @property
    def image_size_px(self) -> int:
        """Side of the PPI images, px."""
        return self._sim.shape[3]

    def render(
        self,
        seed: int = 0,
        frame: int = 0,
        *,
        iq: bool = False,
        doppler_cube: bool = False,
        images: bool = True,
    ) -> Frame:
        """Renders revolution ``frame`` (0-based; time = frame × rotation period) with the
        noise and clutter of ``seed``: the same arguments give the same arrays.

        ``iq`` adds the raw I/Q of every pulse, ``doppler_cube`` the range-Doppler cube
        (``processing.mode = "pulse"``), ``images=False`` skips the 8-bit images. ``seed``
        and ``frame`` are whole numbers 0 … 2**64 - 1."""
        out = self._sim.render(
            _args.seed("seed", seed),
            _args.seed("frame", frame),
            _args.flag("iq", iq),
            _args.flag("doppler_cube", doppler_cube),
            _args.flag("images", images),
        )
        pulses = None
        if out["iq"] is not None:
            pulses = {
                "time_s": out["iq_times_s"],
                "azimuth_deg": out["iq_azimuth_deg"],
                "spoke": out["iq_spoke"],
            }
        return Frame(
            polar_db=out["polar_db"],
            ppi_db=out["ppi_db"],
            ppi_gray=out["ppi_gray"],
            ppi_rgb=out["ppi_rgb"],
            truth=json.loads(out["truth_json"]),
            doppler_cube_db=out["doppler_cube_db"],
            iq=out["iq"],
            iq_pulses=pulses,
            video=out["video"],
            land_mask=out["land_mask"],
            land_polygon=out["land_polygon"],
            structure_mask=out["structure_mask"],
        )

    def __repr__(self) -> str:
        return f"Simulation({self.scene.origin!r})"


def render(scene: Union[Scene, PathLike], seed: int = 0, frame: int = 0) -> Frame:
    """Shorthand for ``Simulation(scene).render(seed, frame)``."""
    seed, frame = _args.seed("seed", seed), _args.seed("frame", frame)  # before building
    return Simulation(scene).render(seed=seed, frame=frame)


def read_spokes(path: PathLike) -> Dict[str, Any]:
    """Reads a spoke stream (``spokes.bin``, written by ``xbandsim render --spoke-format``;
    docs/formats.md): ``spokes_per_revolution`` and, one entry per record in file order,
    ``angle_deg`` (true bearing), ``heading_deg`` (the own ship's; None when the radar has
    none), ``range_m``, ``bits``, ``time_s`` (NumPy arrays) and ``levels`` (uint8, records ×
    samples)."""
    return _xbandsim.read_spokes(os.fspath(path))


__all__ = [
    "Scene",
    "Simulation",
    "Frame",
    "render",
    "read_spokes",
    "data",
    "dataset",
    "XbandsimError",
    "SceneSyntaxError",
    "InvalidFieldError",
    "MissingFieldError",
    "MeshError",
    "EncodeError",
    "XbandsimIOError",
    "DatasetSpecError",
    "DatasetMismatchError",
    "InvalidArgumentError",
    "ArgumentTypeError",
    "IncompleteDatasetWarning",
]
