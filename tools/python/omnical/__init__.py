"""omnical: calibration and correction of non-central catadioptric cameras.

A curved mirror seen by a camera has no single viewpoint: near objects land in the wrong
pixel (parallax). omnical models the real optics. This package is the C++ library's API:
the same jobs as the `omnical` command line, with NumPy arrays in and out.

    import omnical
    sensor = omnical.Sensor.load("sensor.yaml")
    pixels, status = sensor.project(points)          # (N, 3) mm -> (N, 2) px
    ok = status == omnical.ProjectionStatus.OK

Errors: bad input raises omnical.InputError (a ValueError) with the library's one-line
message naming the file and field; long calls accept `progress(stage, done, total)`
(return False to cancel: omnical.Cancelled) and stop cleanly on Ctrl-C
(KeyboardInterrupt). The GIL is released while they run.
"""
import enum as _enum

from . import _omnical
from ._omnical import *  # noqa: F401,F403
from ._omnical import __version__, InputError, Cancelled  # noqa: F401

ProjectionStatus = _enum.IntEnum(
    "ProjectionStatus", {name.upper(): code for code, name in enumerate(_omnical._STATUS_NAMES)}, module=__name__)
ProjectionStatus.__doc__ = """Why a point has no pixel (or a pixel no ray): the values of the status arrays.

OK, OUTSIDE_MIRROR, BEHIND_MIRROR, OCCLUDED_BY_CAMERA, OUTSIDE_IMAGE, MISSES_MIRROR,
NO_SOLUTION, INVALID_INPUT (NaN or infinite input). `status_name()` gives the lower-case
names the CSV and JSON files use."""


def status_name(code):
    """The lower-case name of a status code, as in omnical's CSV and JSON files."""
    return _omnical._STATUS_NAMES[int(code)]
