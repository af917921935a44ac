"""Exceptions raised by xbandsim: one class per kind of library error.

Every class derives from :class:`XbandsimError`. Field errors also derive from
:class:`ValueError`, file errors from :class:`OSError`. Where the error is about a scene or
dataset-spec field, ``field`` holds its dotted path (``"radar.pulse_width_us"``) and
``problem`` its kind (``"out of range"``, ``"unknown choice"``, ...); both are ``None``
otherwise. The message names the scene file (and line and column where known), the field and
its value.
"""

from typing import Optional


class XbandsimError(Exception):
    """Base class of every xbandsim error."""

    field: Optional[str] = None
    problem: Optional[str] = None


class SceneSyntaxError(XbandsimError, ValueError):
    """The scene is not valid TOML, a value has the wrong type or a field is unknown."""


class InvalidFieldError(XbandsimError, ValueError):
    """A field holds a value that is not allowed (negative size, NaN, unknown name...)."""


class MissingFieldError(XbandsimError, ValueError):
    """A field that an object or the radar needs is absent."""


class MeshError(XbandsimError, ValueError):
    """A mesh file could not be read or is not a usable triangle mesh."""


class EncodeError(XbandsimError):
    """Encoding an output (PNG, JSON) failed."""


class XbandsimIOError(XbandsimError, OSError):
    """Reading or writing a file failed."""


class DatasetSpecError(XbandsimError, ValueError):
    """A dataset spec (or a dataset.generate argument) is not valid; ``field`` names it."""


class DatasetMismatchError(XbandsimError):
    """The output folder holds a different dataset (other spec, seed or count)."""


__all__ = [
    "XbandsimError",
    "SceneSyntaxError",
    "InvalidFieldError",
    "MissingFieldError",
    "MeshError",
    "EncodeError",
    "XbandsimIOError",
    "DatasetSpecError",
    "DatasetMismatchError",
]
