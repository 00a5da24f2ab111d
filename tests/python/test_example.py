"""The README's Python example (tools/python/examples/calibrate_and_unwarp.py) runs as a
user would run it and does what it says: its calibration is the one `omnical.calibrate`
files, the printed numbers are those files' numbers, the figures are readable PNGs, and
the panorama is cv2.remap through tables made from the calibrated sensor."""
import json
import pathlib
import subprocess
import sys

import cv2
import numpy as np

import omnical
from conftest import SOURCE_DIR

EXAMPLE = SOURCE_DIR / "tools" / "python" / "examples" / "calibrate_and_unwarp.py"


def test_the_example_calibrates_plots_and_unwarps(tmp_path, data):
    out = tmp_path / "example-out"
    completed = subprocess.run([sys.executable, str(EXAMPLE), str(out), "--quiet"], capture_output=True, text=True,
                               cwd=tmp_path, timeout=600)
    assert completed.returncode == 0, completed.stderr
    lines = completed.stdout.splitlines()

    record = json.loads((out / "calibration" / "calibration.json").read_text())
    assert lines[0].endswith(f"RMS {record['rms_px']:.4f} px per corner (converged)"), lines[0]
    printed = {line.split()[0]: line.split()[1] for line in lines[1:] if line.startswith("  ")}
    assert printed.keys() == record["parameters"].keys()
    for name, parameter in record["parameters"].items():
        assert float(printed[name]) == float(f"{parameter['value']:.8g}")
    # Sub-pixel on exact renders with the distortion held (it is zero in the truth).
    assert record["rms_px"] < 0.2 and "distortion" in record["fixed_blocks"]

    for figure in ["residuals.png", "parallax.png", "panorama.png", "calibration/report/residual_histogram.png"]:
        image = cv2.imread(str(out / figure))
        assert image is not None and image.shape[0] > 100, figure

    # The panorama: tables for n = 7 from the saved sensor, applied to the first image.
    sensor = omnical.Sensor.load(out / "calibration" / "sensor.yaml")
    map_x, map_y = omnical.remap_tables(sensor, "panorama", n=7, size=(1024, 256))
    first = sorted((data / "rendered" / "ohte-sph-near").glob("*.png"))[0]
    expected = cv2.remap(cv2.imread(str(first)), map_x, map_y, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT)
    np.testing.assert_array_equal(cv2.imread(str(out / "panorama.png")), expected)
    parallax = omnical.parallax(sensor, n=7)
    assert f"up to {parallax.max_abs_error_px:.3f} px" in completed.stdout
