"""omnical.Sensor: files, parameters, and projection of NumPy arrays, checked against the
CLI's `project` / `unproject` output and against geometry (a projected point lies on the
ray of its pixel)."""
import csv
import sys
import threading
import time

import numpy as np
import pytest

import omnical
from conftest import cli_error

SENSORS = ["ohte-sph.yaml", "ohte-edi.yaml", "ohte-svp.yaml", "ohte-sph-misaligned.yaml"]


def visible_points(sensor, count, seed=1):
    """Points the sensor sees: rays of random pixels, 200-3000 mm along."""
    rng = np.random.default_rng(seed)
    width, height = sensor.image_size
    pixels = np.column_stack([rng.uniform(0, width - 1, 4 * count), rng.uniform(0, height - 1, 4 * count)])
    origins, directions, status = sensor.unproject(pixels)
    keep = status == omnical.ProjectionStatus.OK
    return origins[keep][:count] + rng.uniform(200, 3000, (count, 1)) * directions[keep][:count]


def read_cli_csv(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


@pytest.mark.parametrize("name", SENSORS)
def test_project_and_unproject_equal_the_cli(name, data, cli, tmp_path):
    sensor = omnical.Sensor.load(data / "sensors" / name)
    points = np.vstack([visible_points(sensor, 50), [[0.0, 0.0, 1e6], [5000.0, 0.0, -100.0]]])
    np.savetxt(tmp_path / "points.csv", points, delimiter=",", fmt="%.17g")
    completed = cli("project", "--sensor", data / "sensors" / name, "--points", tmp_path / "points.csv",
                    "--out", tmp_path / "pixels.csv")
    assert completed.returncode == 0, completed.stderr
    header, rows = read_cli_csv(tmp_path / "pixels.csv")
    assert header == ["u", "v", "status"]
    pixels, status = sensor.project(points)
    assert pixels.shape == (len(points), 2) and pixels.dtype == np.float64
    assert status.shape == (len(points),)
    assert [omnical.status_name(s) for s in status] == [row[2] for row in rows]
    cli_pixels = np.array([[float(row[0]), float(row[1])] for row in rows])
    # The CLI projects point by point (the scalar solver), Python through the batch path;
    # both converge to the same reflection point, to ~1e-10 px (model/batch_projection.h).
    np.testing.assert_allclose(pixels, cli_pixels, rtol=0, atol=1e-9, equal_nan=True)
    assert np.isnan(pixels[status != omnical.ProjectionStatus.OK]).all()

    ok = status == omnical.ProjectionStatus.OK
    np.savetxt(tmp_path / "uv.csv", pixels[ok], delimiter=",", fmt="%.17g")
    completed = cli("unproject", "--sensor", data / "sensors" / name, "--pixels", tmp_path / "uv.csv",
                    "--out", tmp_path / "rays.csv")
    assert completed.returncode == 0, completed.stderr
    _, rows = read_cli_csv(tmp_path / "rays.csv")
    origins, directions, ray_status = sensor.unproject(pixels[ok])
    # Same solver tolerance as above, in mm and in direction cosines.
    np.testing.assert_allclose(origins, [[float(v) for v in row[0:3]] for row in rows], rtol=0, atol=1e-9)
    np.testing.assert_allclose(directions, [[float(v) for v in row[3:6]] for row in rows], rtol=0, atol=1e-11)
    assert [omnical.status_name(s) for s in ray_status] == [row[6] for row in rows]


@pytest.mark.parametrize("name", SENSORS)
def test_a_projected_point_lies_on_its_pixels_ray(name, data):
    sensor = omnical.Sensor.load(data / "sensors" / name)
    points = visible_points(sensor, 2000, seed=2)
    pixels, status = sensor.project(points)
    assert (status == omnical.ProjectionStatus.OK).all()
    origins, directions, ray_status = sensor.unproject(pixels)
    assert (ray_status == omnical.ProjectionStatus.OK).all()
    np.testing.assert_allclose(np.linalg.norm(directions, axis=1), 1.0, atol=1e-12)
    offset = points - origins
    miss_mm = np.linalg.norm(offset - np.sum(offset * directions, axis=1)[:, None] * directions, axis=1)
    # The solvers converge to ~1e-10 px; at 3 m that is well under a micrometre.
    assert miss_mm.max() < 1e-6


def test_nan_and_infinite_points_give_invalid_input_not_an_exception(data):
    sensor = omnical.Sensor.load(data / "sensors" / "ohte-sph.yaml")
    points = np.array([[np.nan, 0, 500], [0, np.inf, 500], [400.0, -150.0, 60.0], [-np.inf, 1, 1]])
    pixels, status = sensor.project(points)
    assert list(status) == [omnical.ProjectionStatus.INVALID_INPUT, omnical.ProjectionStatus.INVALID_INPUT,
                            omnical.ProjectionStatus.OK, omnical.ProjectionStatus.INVALID_INPUT]
    assert np.isnan(pixels[[0, 1, 3]]).all() and np.isfinite(pixels[2]).all()
    _, _, ray_status = sensor.unproject(np.array([[np.nan, 1.0], [500.0, 500.0]]))
    assert ray_status[0] == omnical.ProjectionStatus.INVALID_INPUT


def test_empty_input_gives_empty_output(data):
    sensor = omnical.Sensor.load(data / "sensors" / "ohte-sph.yaml")
    pixels, status = sensor.project(np.zeros((0, 3)))
    assert pixels.shape == (0, 2) and status.shape == (0,)


def test_any_layout_and_real_dtype_is_read_correctly(data):
    sensor = omnical.Sensor.load(data / "sensors" / "ohte-sph-misaligned.yaml")
    points = visible_points(sensor, 300, seed=3)
    reference, _ = sensor.project(points)
    # Non-contiguous: every other row of a wider array, and a column-major copy.
    wide = np.zeros((2 * len(points), 5))
    wide[::2, 1:4] = points
    np.testing.assert_array_equal(sensor.project(wide[::2, 1:4])[0], reference)
    np.testing.assert_array_equal(sensor.project(np.asfortranarray(points))[0], reference)
    np.testing.assert_array_equal(sensor.project(points[::-1])[0], reference[::-1])
    read_only = points.copy()
    read_only.flags.writeable = False
    np.testing.assert_array_equal(sensor.project(read_only)[0], reference)
    np.testing.assert_array_equal(sensor.project(points.tolist())[0], reference)
    # float32 and integers are converted to float64: same as projecting the converted values.
    single = points.astype(np.float32)
    np.testing.assert_array_equal(sensor.project(single)[0], sensor.project(single.astype(np.float64))[0])
    whole = np.rint(points).astype(np.int32)
    np.testing.assert_array_equal(sensor.project(whole)[0], sensor.project(whole.astype(np.float64))[0])
    # The input is not modified, the outputs own their memory and outlive the sensor.
    before = points.copy()
    pixels, status = sensor.project(points)
    del sensor
    np.testing.assert_array_equal(points, before)
    np.testing.assert_array_equal(pixels, reference)


@pytest.mark.parametrize("bad, message", [
    (np.zeros(3), "points: expected an (N, 3) array of numbers, got shape (3,) (one point: reshape(1, 3))"),
    (np.zeros((4, 2)), "points: expected an (N, 3) array of numbers, got shape (4, 2)"),
    (np.zeros((2, 3, 1)), "points: expected an (N, 3) array of numbers, got shape (2, 3, 1)"),
    (np.zeros((2, 3), dtype=complex), "points: expected an (N, 3) array of numbers, got dtype complex128"),
    (np.array([["a", "b", "c"]]), "points: expected an (N, 3) array of numbers, got dtype <U1"),
    (np.array([[None, 1, 2]], dtype=object), "points: expected an (N, 3) array of numbers, got dtype object"),
    (np.ones((1, 3), dtype=bool), "points: expected an (N, 3) array of numbers, got dtype bool"),
])
def test_arrays_of_the_wrong_shape_or_kind_are_refused_clearly(data, bad, message):
    sensor = omnical.Sensor.load(data / "sensors" / "ohte-sph.yaml")
    with pytest.raises(omnical.InputError) as error:
        sensor.project(bad)
    assert str(error.value) == message
    with pytest.raises(omnical.InputError, match=r"^pixels: expected an \(N, 2\) array of numbers"):
        sensor.unproject(np.zeros((3, 3)))


def test_parameters_round_trip_and_build_the_same_sensor(data, tmp_path):
    for name in SENSORS:
        sensor = omnical.Sensor.load(data / "sensors" / name)
        parameters = sensor.parameters
        assert set(parameters) == {"camera", "mirror", "pose"}
        rebuilt = omnical.Sensor.from_parameters(parameters)
        assert rebuilt.to_yaml() == sensor.to_yaml()
        points = visible_points(sensor, 100, seed=4)
        np.testing.assert_array_equal(rebuilt.project(points)[0], sensor.project(points)[0])
        sensor.save(tmp_path / name)
        assert omnical.Sensor.load(str(tmp_path / name)).to_yaml() == sensor.to_yaml()
        assert omnical.Sensor.from_yaml(sensor.to_yaml()).to_yaml() == sensor.to_yaml()


def test_parameters_reflect_the_file_and_edits_take_effect(data):
    sensor = omnical.Sensor.load(data / "sensors" / "ohte-sph.yaml")
    parameters = sensor.parameters
    # The file's values (datasets-synthetic/sensors/ohte-sph.yaml).
    assert parameters["mirror"]["profile"] == "sphere" and parameters["mirror"]["rim_radius"] == 43.9
    assert parameters["pose"]["m"] == 180.429 and parameters["camera"]["image_size"] == [1000, 1000]
    assert sensor.profile == "sphere" and sensor.lens == "pinhole" and sensor.is_axial
    assert sensor.rim_radius_mm == 43.9 and sensor.image_size == (1000, 1000)
    # An edited mirror distance m is the new sensor's: the same point lands elsewhere.
    parameters["pose"]["m"] = np.float64(200.0)
    farther = omnical.Sensor.from_parameters(parameters)
    assert farther.parameters["pose"]["m"] == 200.0 and "sphere" in repr(farther)
    point = visible_points(sensor, 1, seed=6)
    assert np.linalg.norm(farther.project(point)[0] - sensor.project(point)[0]) > 1.0
    assert not omnical.Sensor.load(data / "sensors" / "ohte-sph-misaligned.yaml").is_axial


def test_bad_parameters_and_files_raise_input_error_with_the_clis_message(data, cli, tmp_path):
    parameters = omnical.Sensor.load(data / "sensors" / "ohte-sph.yaml").parameters
    parameters["mirror"]["A"] = float("nan")
    with pytest.raises(omnical.InputError, match=r"^parameters: mirror.A: not a finite number$"):
        omnical.Sensor.from_parameters(parameters)
    parameters["mirror"]["A"] = object()
    with pytest.raises(omnical.InputError, match=r"^parameters: mirror.A: expected a number"):
        omnical.Sensor.from_parameters(parameters)
    np.savetxt(tmp_path / "p.csv", [[1.0, 2.0, 300.0]], delimiter=",")
    broken = tmp_path / "broken.yaml"
    broken.write_text("camera: {model: pinhole\n")
    negative = tmp_path / "negative.yaml"
    negative.write_text((data / "sensors" / "ohte-sph.yaml").read_text().replace("A: 49.95819999999999", "A: -2"))
    for path in [tmp_path / "missing.yaml", broken, negative, tmp_path]:
        expected = cli_error(cli("project", "--sensor", path, "--points", tmp_path / "p.csv"))
        with pytest.raises(omnical.InputError) as error:
            omnical.Sensor.load(path)
        assert str(error.value) == expected
        assert isinstance(error.value, ValueError)


def test_projection_releases_the_gil(data):
    """With the switch interval at 100 s the main thread keeps the GIL while it runs Python,
    so the counting thread (which yields at every step) runs only while the call has
    released the GIL: its counter must move during a 2 x 10^6-point projection."""
    sensor = omnical.Sensor.load(data / "sensors" / "ohte-sph-misaligned.yaml")
    points = np.repeat(visible_points(sensor, 1000, seed=5), 2000, axis=0)
    counter, stop = [0], threading.Event()

    def count():
        while not stop.is_set():
            counter[0] += 1
            time.sleep(0)
    previous = sys.getswitchinterval()
    worker = threading.Thread(target=count)
    try:
        worker.start()
        sys.setswitchinterval(100.0)
        before = counter[0]
        sensor.project(points)
        during = counter[0] - before
    finally:
        sys.setswitchinterval(previous)
        stop.set()
        worker.join()
    assert during > 0


def test_status_enum_matches_the_files_names():
    assert [s.name.lower() for s in omnical.ProjectionStatus] == [
        "ok", "outside_mirror", "behind_mirror", "occluded_by_camera", "outside_image", "misses_mirror",
        "no_solution", "invalid_input"]
    assert omnical.ProjectionStatus.INVALID_INPUT == 7 and omnical.status_name(2) == "behind_mirror"
    assert issubclass(omnical.InputError, ValueError)


def test_the_registrys_choices_and_the_even_asphere_of_a_catalogue(data):
    """The profile list comes from the model registry; the even asphere with the
    hyperboloid's conic constant is the shipped SVP sensor (to 1e-9 px, the C++ test's bound)."""
    assert omnical.PROFILES == ["sphere", "polynomial", "hyperboloid", "paraboloid", "tabulated", "even_asphere",
                                "spline"]
    assert omnical.LENSES == ["pinhole", "orthographic"]
    assert "tabulated" not in omnical.DESIGN_PROFILES and "even_asphere" in omnical.DESIGN_PROFILES
    svp = omnical.Sensor.load(data / "sensors" / "ohte-svp.yaml")
    parameters = svp.parameters
    a, b = parameters["mirror"]["A"], parameters["mirror"]["B"]
    parameters["mirror"] = {"profile": "even_asphere", "rim_radius": parameters["mirror"]["rim_radius"],
                            "R": a * a / b, "k": -1.0 - a * a / (b * b)}
    asphere = omnical.Sensor.from_parameters(parameters)
    assert asphere.profile == "even_asphere"
    points = visible_points(svp, 500, seed=9)
    pixels, status = svp.project(points)
    twin_pixels, twin_status = asphere.project(points)
    np.testing.assert_array_equal(status, twin_status)
    ok = status == omnical.ProjectionStatus.OK
    assert ok.sum() > 400
    assert np.abs(pixels[ok] - twin_pixels[ok]).max() < 1e-9
    parameters["mirror"]["k"] = 10.0  # an oblate ellipsoid that ends before the rim
    with pytest.raises(omnical.InputError, match="R / sqrt"):
        omnical.Sensor.from_parameters(parameters)
