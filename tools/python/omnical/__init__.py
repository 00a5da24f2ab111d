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

class ProjectionStatus(_enum.IntEnum):
    """Why a point has no pixel (or a pixel no ray): the values of the status arrays that
    Sensor.project and Sensor.unproject return (compare: status == ProjectionStatus.OK).
    `status_name()` gives the lower-case names omnical's CSV and JSON files use."""
    OK = 0
    OUTSIDE_MIRROR = 1       # the reflection point would lie beyond the mirror rim
    BEHIND_MIRROR = 2        # the point is on the far side of the mirror surface
    OCCLUDED_BY_CAMERA = 3   # the ray from the mirror to the point hits the camera body
    OUTSIDE_IMAGE = 4        # the pixel falls outside the sensor's image
    MISSES_MIRROR = 5        # (unproject) the lens ray does not head towards the mirror
    NO_SOLUTION = 6          # the solver did not converge
    INVALID_INPUT = 7        # NaN or infinite input


# The library's own list (model/types.h) decides: a status added there fails here at import.
if [s.name.lower() for s in ProjectionStatus] != list(_omnical._STATUS_NAMES):
    raise ImportError(f"omnical: ProjectionStatus differs from the library's {_omnical._STATUS_NAMES}")


def status_name(code):
    """The lower-case name of a status code, as in omnical's CSV and JSON files."""
    return _omnical._STATUS_NAMES[int(code)]
