"""The correction jobs from Python against the omnical CLI (same files, same numbers) and
against the documented screen geometry (correction/virtual_screen.h, model/types.h)."""
import json
import math

import cv2
import numpy as np
import pytest

import omnical
from conftest import cli_error

SPH = "sensors/ohte-sph.yaml"
MISALIGNED = "sensors/ohte-sph-misaligned.yaml"
IMAGE = "rendered/ohte-sph-near/near000.png"  # 1000 x 1000, the ohte-sph sensor's image

# Two views on small screens: the axial sensor's panorama (the axial-symmetry path) and the
# misaligned sensor's perspective view (the interpolated grid).
VIEWS = {
    "panorama": (SPH, ["--view", "panorama", "--size", "256x64", "--n", "7"],
                 dict(view="panorama", size="256x64", n=7)),
    "perspective": (MISALIGNED, ["--view", "perspective", "--size", "80x60", "--distance-mm", "400", "--pan-deg", "30",
                                 "--tilt-deg", "-10"],
                    dict(view="perspective", size=(80, 60), distance_mm=400, pan_deg=30, tilt_deg=-10)),
}


def run_ok(cli, *args):
    done = cli(*args)
    assert done.returncode == 0, done.stderr
    return done


def load_json(path):
    return json.loads(path.read_text())


def same_files(ours, theirs, names):
    for name in names:
        assert (ours / name).read_bytes() == (theirs / name).read_bytes(), name


def infinite(value):
    return math.inf if value == "infinity" else value


@pytest.mark.parametrize("name", VIEWS)
def test_remap_equals_cli_bit_for_bit(cli, data, tmp_path, name):
    sensor, flags, kwargs = VIEWS[name]
    path = str(data / sensor)
    run_ok(cli, "remap", "--sensor", path, *flags, "--format", "npy,opencv", "--out", tmp_path / "cli")
    result = omnical.remap(path, **kwargs)
    for table, ours in (("map_x", result.map_x), ("map_y", result.map_y)):
        theirs = np.load(tmp_path / "cli" / f"{table}.npy")
        assert ours.dtype == np.float32 and ours.shape == theirs.shape
        assert np.array_equal(ours, theirs)
    result.save(tmp_path / "py", formats=("npy", "opencv"))  # names the sensor as remap() read it, like the CLI
    same_files(tmp_path / "py", tmp_path / "cli",
               ["map_x.npy", "map_y.npy", "maps.yml.gz", "maps_fixed.yml.gz", "remap_error.png"])
    ours, theirs = load_json(tmp_path / "py" / "maps.json"), load_json(tmp_path / "cli" / "maps.json")
    for description in (ours, theirs):
        del description["generation_seconds"]  # timing
    assert ours == theirs
    # The result's fields are the numbers maps.json holds.
    assert result.exactness_px == theirs["exactness_check"]["max_error_px"]
    assert result.valid_fraction == theirs["valid_fraction"]
    assert result.v0_mm == theirs["v0_mm"] and result.v0_searched == theirs["v0_searched"]
    assert result.method == theirs["method"]
    assert result.size == tuple(theirs["view"]["size_px"])
    assert result.generation_seconds > 0
    assert result.error_at_other_distances == [
        (infinite(e["n"]), infinite(e["distance_mm"]), e["max_px"], e["rms_px"], e["samples"])
        for e in theirs["error_at_other_distances"]]


def rotation_xy(tilt_deg):
    """Ry(tilt_y) Rx(tilt_x) of model/types.h."""
    ax, ay = np.radians(tilt_deg)
    rx = np.array([[1, 0, 0], [0, math.cos(ax), -math.sin(ax)], [0, math.sin(ax), math.cos(ax)]])
    ry = np.array([[math.cos(ay), 0, math.sin(ay)], [0, 1, 0], [-math.sin(ay), 0, math.cos(ay)]])
    return ry @ rx


def direction(omega, phi):
    """d(Omega, phi) of virtual_screen.h (mirror frame)."""
    return np.stack([np.sin(omega) * np.cos(phi), np.sin(omega) * np.sin(phi), -np.cos(omega)], axis=-1)


def panorama_directions(cols, rows, width, height, azimuth0_deg, top_deg, bottom_deg):
    phi = np.radians(azimuth0_deg - 360.0 * (cols + 0.5) / width)
    top, bottom = math.tan(math.radians(top_deg)), math.tan(math.radians(bottom_deg))
    elevation = np.arctan(top + (bottom - top) * (rows + 0.5) / height)
    return direction(elevation + math.pi / 2, phi)


def perspective_directions(cols, rows, width, height, pan_deg, tilt_deg, hfov_deg):
    f = (width / 2) / math.tan(math.radians(hfov_deg) / 2)
    forward = direction(math.radians(tilt_deg) + math.pi / 2, math.radians(pan_deg))
    right = np.cross(forward, [0, 0, 1])
    right /= np.linalg.norm(right)
    down = np.cross(forward, right)
    d = forward + (np.outer(cols - (width - 1) / 2, right) + np.outer(rows - (height - 1) / 2, down)) / f
    return d / np.linalg.norm(d, axis=1, keepdims=True)


# Documented bounds: the interpolated grid and the axial shortcut promise 0.01 px against
# exact projection (remap_table.h); per-pixel tables differ only by float32 rounding of
# ~1000 px values (6e-5 px) and the batch vs scalar projection (~1e-9 px): 1e-3 px.
@pytest.mark.parametrize("case", ["panorama", "panorama-per-pixel", "perspective"])
def test_remap_entries_are_projections_of_screen_points(data, case):
    v0_mm = 11.0  # V0 and all screen parameters given, so nothing here comes from the code under test
    if case.startswith("panorama"):
        sensor = omnical.Sensor.load(data / SPH)
        distance_mm = 7 * sensor.rim_radius_mm
        result = omnical.remap(sensor, "panorama", size=(180, 40), azimuth0_deg=150, elevation_deg=(55, -70),
                               n=7, v0_mm=v0_mm, per_pixel=case.endswith("per-pixel"))
        rows, cols = np.mgrid[0:40:3, 0:180:7]
        rows, cols = rows.ravel(), cols.ravel()
        d = panorama_directions(cols, rows, 180, 40, 150, 55, -70)  # beyond the field (-60 .. 45 deg)
    else:
        sensor = omnical.Sensor.load(data / MISALIGNED)
        distance_mm = 400.0
        result = omnical.remap(sensor, "perspective", size=(80, 60), pan_deg=30, tilt_deg=-10, hfov_deg=70,
                               distance_mm=distance_mm, v0_mm=v0_mm)
        rows, cols = np.mgrid[0:60:3, 0:80:3]
        rows, cols = rows.ravel(), cols.ravel()
        d = perspective_directions(cols, rows, 80, 60, 30, -10, 70)
    pose = sensor.parameters["pose"]
    points_in_mirror = np.array([0, 0, v0_mm]) + distance_mm * d  # on the sphere around V0
    points_in_camera = points_in_mirror @ rotation_xy(pose["tilt_deg"]).T + [*pose["decenter_mm"], pose["m"]]
    pixels, status = sensor.project(points_in_camera)
    table = np.stack([result.map_x[rows, cols], result.map_y[rows, cols]], axis=1).astype(np.float64)
    valid = table[:, 0] != -1
    assert valid.mean() > 0.5 and (case == "perspective" or valid.mean() < 0.95)
    # -1 exactly where the object point has no pixel.
    assert np.array_equal(valid, status == omnical.ProjectionStatus.OK)
    error = np.abs(table[valid] - pixels[valid]).max()
    assert error < (1e-3 if case == "panorama-per-pixel" else 0.01), error
    assert result.method == {"panorama": "axial symmetry", "panorama-per-pixel": "per pixel",
                             "perspective": "interpolated grid"}[case]


def test_remap_result_properties_progress_and_cancel(data):
    sensor = omnical.Sensor.load(data / SPH)
    seen = []
    result = omnical.remap(sensor, "panorama", size=(128, 32), n=7, progress=lambda *a: seen.append(a))
    assert {stage for stage, _, _ in seen} == {"remap table", "remap error"}
    assert ("remap table", 32, 32) in seen  # one step per output row
    assert result.map_x.shape == (32, 128) and result.size == (128, 32)
    # -1 marks the output pixels that see no mirror (both tables), the rest are in the
    # image, which spans [-0.5, 999.5] (pixel centres at integers).
    invalid = result.map_x == -1
    assert np.array_equal(invalid, result.map_y == -1)
    assert result.valid_fraction == pytest.approx(1 - invalid.mean(), abs=1e-12)
    for table in (result.map_x, result.map_y):
        assert np.all((table[~invalid] >= -0.5) & (table[~invalid] <= 999.5))
    # Exact at its own distance (the error vanishes there), wrong elsewhere.
    errors = {n: max_px for n, _, max_px, _, _ in result.error_at_other_distances}
    assert list(errors) == [1.5, 2, 3, 5, 7, 10, 20, 40, 100, math.inf]
    assert errors[7] < 1e-9 and errors[2] > 0.1 and result.exactness_px < 0.01
    assert result.v0_searched
    # settings are remap()'s keywords for the same table.
    settings = result.settings
    assert settings["view"] == "panorama" and settings["size"] == "128x32" and settings["surface"] == "sphere"
    assert settings["distance_mm"] == pytest.approx(7 * sensor.rim_radius_mm, rel=1e-15)
    again = omnical.remap(sensor, **settings)
    assert np.array_equal(again.map_x, result.map_x) and np.array_equal(again.map_y, result.map_y)
    assert not again.v0_searched and again.v0_mm == result.v0_mm
    # remap_tables: the short form.
    map_x, map_y = omnical.remap_tables(data / SPH, "panorama", "sphere", size=(128, 32), n=7)
    assert np.array_equal(map_x, result.map_x) and np.array_equal(map_y, result.map_y)
    map_x, _ = omnical.remap_tables(sensor, "lonlat", "cylinder", size=(64, 16), n=5)
    assert map_x.shape == (16, 64)
    inf = omnical.remap(sensor, "equiangular", size=(48, 48), infinity=True)
    assert inf.settings["infinity"] and "distance_mm" not in inf.settings and "omega_max_deg" in inf.settings
    plane = omnical.remap(sensor, "perspective", size=(40, 30), tilt_deg=-20, distance_mm=300, surface="plane",
                          plane_normal=(0, 0, -1))
    assert plane.settings["plane_normal"] == (0.0, 0.0, -1.0)
    # A callback returning False cancels.
    with pytest.raises(omnical.Cancelled):
        omnical.remap(sensor, size=(128, 32), n=7, progress=lambda stage, done, total: done < 3)


def test_remap_save_from_a_sensor_object(data, tmp_path):
    sensor = omnical.Sensor.load(data / SPH)
    result = omnical.remap(sensor, size=(64, 16), n=7)
    result.save(tmp_path / "a", formats="ffmpeg")
    description = load_json(tmp_path / "a" / "maps.json")
    assert description["sensor"]["file"] == "" and description["sensor"]["yaml"] == sensor.to_yaml()
    assert sorted(p.name for p in (tmp_path / "a").iterdir()) == ["maps.json", "remap_error.png", "xmap.pgm", "ymap.pgm"]
    result.save(tmp_path / "b", sensor_path=data / SPH)
    description = load_json(tmp_path / "b" / "maps.json")
    assert description["sensor"]["file"] == str(data / SPH)
    assert description["sensor"]["yaml"] == (data / SPH).read_text()
    assert (tmp_path / "b" / "maps.yml.gz").exists()


def test_parallax_equals_cli(cli, data, tmp_path):
    path = str(data / SPH)
    run_ok(cli, "parallax", "--sensor", path, "--n", 7, "--out", tmp_path / "cli")
    seen = []
    result = omnical.parallax(path, n=7, progress=lambda *a: seen.append(a))
    assert seen[-1] == ("parallax map", 1000, 1000)  # one step per image row
    result.save(tmp_path / "py")
    same_files(tmp_path / "py", tmp_path / "cli", ["parallax.csv", "parallax.json", "parallax.png", "error_map.png"])
    # The same numbers as the CLI's files: the JSON holds full doubles (1e-12 relative
    # leaves room for nothing but rounding), the CSV 10 significant digits (5e-10).
    summary = load_json(tmp_path / "cli" / "parallax.json")
    for ours, key in ((result.distance_mm, "object_distance_mm"), (result.n, "n"), (result.v0_mm, "v0_mm"),
                      (result.max_abs_error_px, "max_abs_error_px"), (result.max_abs_error_deg, "max_abs_error_deg"),
                      (result.map_max_abs_error_px, "map_max_abs_error_px")):
        assert ours == pytest.approx(summary[key], rel=1e-12), key
    assert result.v0_searched and result.axial and summary["analysed_as"] == "axial"
    curve = np.loadtxt(tmp_path / "cli" / "parallax.csv", delimiter=",", skiprows=1)
    assert len(curve) == 540  # the default samples
    for column, ours in enumerate((result.omega_deg, result.x_mm, result.error_deg, result.error_px)):
        np.testing.assert_allclose(ours, curve[:, column], rtol=5e-10, atol=1e-12)
    assert np.abs(result.error_px).max() == result.max_abs_error_px
    error_map = result.error_map
    assert error_map.shape == (1000, 1000) and error_map.dtype == np.float32
    assert np.isnan(error_map[0, 0])  # the image corner sees no mirror
    assert np.nanmax(np.abs(error_map)) == pytest.approx(result.map_max_abs_error_px, rel=1e-6)  # float32 map
    # The same object by distance, V0 given: the same curve.
    again = omnical.parallax(omnical.Sensor.load(path), distance_mm=result.distance_mm, v0_mm=result.v0_mm, samples=540,
                             threads=1)
    assert not again.v0_searched and np.array_equal(again.error_px, result.error_px)
    again.save(tmp_path / "again", sensor_path=path)
    assert load_json(tmp_path / "again" / "parallax.json")["sensor"] == path


def test_maps_error_equals_cli(cli, data, tmp_path):
    path = str(data / SPH)
    maps = str(tmp_path / "maps")
    run_ok(cli, "remap", "--sensor", path, "--view", "panorama", "--size", "128x32", "--n", 7, "--out", maps)
    run_ok(cli, "parallax", "--maps", maps, "--out", tmp_path / "cli")
    seen = []
    result = omnical.maps_error(maps, progress=lambda *a: seen.append(a))
    result.save(tmp_path / "py")
    same_files(tmp_path / "py", tmp_path / "cli", ["maps-error.csv", "maps-error.json", "maps-error.png"])
    summary = load_json(tmp_path / "cli" / "maps-error.json")
    assert [(n, max_px, rms_px) for n, _, max_px, rms_px, _ in result.errors] == [
        (infinite(e["n"]), e["max_px"], e["rms_px"]) for e in summary["error"]]
    assert result.errors[-1][:2] == (math.inf, math.inf) and seen[-1][0] == "remap error"
    assert result.max_px_at(2) == next(e["max_px"] for e in summary["error"] if e["n"] == 2)
    assert math.isnan(result.max_px_at(2.5))
    assert result.made_for == "a sphere at n = 7.000" and result.maps_dir == maps
    assert result.v0_mm == summary["v0_mm"] and result.rim_radius_mm == 43.9
    # Another sensor of the same image: the given one is evaluated.
    run_ok(cli, "parallax", "--maps", maps, "--sensor", path, "--out", tmp_path / "cli2")
    omnical.maps_error(maps, path, threads=1).save(tmp_path / "py2")
    same_files(tmp_path / "py2", tmp_path / "cli2", ["maps-error.csv"])


def test_unwarp_equals_cli_and_cv2_remap(cli, data, tmp_path):
    path, image_path = str(data / SPH), str(data / IMAGE)
    maps = str(tmp_path / "maps")
    run_ok(cli, "remap", "--sensor", path, "--view", "panorama", "--size", "256x64", "--n", 7, "--out", maps)
    image = cv2.imread(image_path, cv2.IMREAD_UNCHANGED)
    assert image.dtype == np.uint8 and image.shape == (1000, 1000)
    for interpolation in ("linear", "cubic", "nearest"):
        run_ok(cli, "unwarp", "--maps", maps, "--input", image_path, "--interpolation", interpolation,
               "--out", tmp_path / f"{interpolation}.png")
        theirs = cv2.imread(str(tmp_path / f"{interpolation}.png"), cv2.IMREAD_UNCHANGED)
        assert np.array_equal(omnical.unwarp(image, maps, interpolation=interpolation), theirs), interpolation
    unwarped = omnical.unwarp(image, maps)
    assert unwarped.shape == (64, 256) and unwarped.dtype == np.uint8
    # cv2.remap of the same tables: the fixed-point pair for linear, the float maps for nearest.
    result = omnical.remap(path, size=(256, 64), n=7)
    map1, map2 = cv2.convertMaps(result.map_x, result.map_y, cv2.CV_16SC2)
    expected = cv2.remap(image, map1, map2, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT)
    assert np.array_equal(unwarped, expected)
    assert np.array_equal(omnical.unwarp(image, result), expected)
    assert np.array_equal(omnical.unwarp(image, (result.map_x, result.map_y)), expected)
    nearest = cv2.remap(image, result.map_x, result.map_y, cv2.INTER_NEAREST, borderMode=cv2.BORDER_CONSTANT)
    assert np.array_equal(omnical.unwarp(image, result, interpolation="nearest"), nearest)
    # Unwarper: from a view made now, from tables; colour and non-contiguous images.
    seen = []
    unwarper = omnical.Unwarper.from_view(path, size="256x64", n=7, progress=lambda *a: seen.append(a))
    assert seen[-1] == ("remap table", 64, 64)
    assert unwarper.size == (256, 64) and np.array_equal(unwarper.apply(image), expected)
    from_tables = omnical.Unwarper.from_tables(result.map_x, result.map_y, (1000, 1000))
    assert np.array_equal(from_tables.apply(image), expected)
    bgr = np.dstack([image, image // 2, 255 - image])
    colour = omnical.unwarp(bgr, maps)
    assert colour.shape == (64, 256, 3)
    for channel in range(3):
        assert np.array_equal(colour[:, :, channel], cv2.remap(bgr[:, :, channel], map1, map2, cv2.INTER_LINEAR))
    rgb_view = bgr[:, :, ::-1]  # not C-contiguous: copied
    assert np.array_equal(omnical.unwarp(rgb_view, maps), colour[:, :, ::-1])
    padded = np.zeros((1000, 1010), np.uint8)
    padded[:, :1000] = image
    assert not padded[:, :1000].flags.c_contiguous
    assert np.array_equal(omnical.unwarp(padded[:, :1000], maps), unwarped)
    with pytest.raises(omnical.InputError, match="^image: "):
        omnical.unwarp(image.astype(np.float32), maps)
    with pytest.raises(omnical.InputError, match=r"^image: is 999 x 1000 px but the sensor's image is 1000 x 1000 px$"):
        omnical.unwarp(image[:, :999], maps)
    # Frames (e.g. of a video) with progress.
    frames = [image, image[::-1].copy(), 255 - image]
    written, seen = [], []
    count = omnical.Unwarper.from_maps(maps).apply_frames(iter(frames), written.append, total=3,
                                                         progress=lambda *a: seen.append(a))
    assert count == 3 and seen[-1] == ("unwarp", 3, 3)
    assert all(np.array_equal(w, omnical.unwarp(f, maps)) for w, f in zip(written, frames))
    with pytest.raises(omnical.InputError, match="^camera: has no readable frames$"):
        unwarper.apply_frames([], written.append, source="camera")
    # Frames are read ahead on another thread: a reader that refills one buffer (as video
    # readers may) must still get each frame unwarped as it was when yielded.
    def refilled():
        buffer = np.empty_like(image)
        for frame in frames * 4:
            buffer[...] = frame
            yield buffer
    written = []
    assert unwarper.apply_frames(refilled(), written.append) == 12
    assert all(np.array_equal(w, omnical.unwarp(f, maps)) for w, f in zip(written, frames * 4))
    # An exception in write (called on the writer thread) reaches the caller as itself.
    def full(_):
        raise OSError("disk full")
    with pytest.raises(OSError, match="^disk full$"):
        unwarper.apply_frames(iter(frames * 10), full)


def mei_project(parameters, central_from_mirror, v0_mm, points_in_mirror):
    """cv::omnidir's projection (Mei & Rives 2007) from central.json's parameters."""
    p = parameters
    x = (points_in_mirror - [0, 0, v0_mm]) @ np.asarray(central_from_mirror).T
    xs = x / np.linalg.norm(x, axis=1, keepdims=True)
    u, v = xs[:, 0] / (xs[:, 2] + p["xi"]), xs[:, 1] / (xs[:, 2] + p["xi"])
    r2 = u * u + v * v
    radial = 1 + p["k1"] * r2 + p["k2"] * r2 * r2
    ud = u * radial + 2 * p["p1"] * u * v + p["p2"] * (r2 + 2 * u * u)
    vd = v * radial + p["p1"] * (r2 + 2 * v * v) + 2 * p["p2"] * u * v
    return np.stack([p["fx"] * ud + p["skew"] * vd + p["cx"], p["fy"] * vd + p["cy"]], axis=1)


@pytest.mark.parametrize("model,flags,kwargs", [("mei", [], {}), ("ocamcalib", ["--n", 7], dict(n=7))])
def test_export_central_equals_cli(cli, data, tmp_path, model, flags, kwargs):
    path = str(data / SPH)
    run_ok(cli, "export-central", "--sensor", path, "--model", model, "--step-px", 32, *flags, "--out", tmp_path / "cli")
    seen = []
    result = omnical.export_central(path, model=model, step_px=32, progress=lambda *a: seen.append(a), **kwargs)
    assert seen[-1] == ("export-central", 11, 11)
    result.save(tmp_path / "py")
    model_file = "omnidir.yml" if model == "mei" else "calib_results.txt"
    same_files(tmp_path / "py", tmp_path / "cli", [model_file, "central.json", "central_error.csv", "central_error.png"])
    summary = load_json(tmp_path / "cli" / "central.json")
    assert result.model == model and result.v0_mm == summary["v0_mm"]
    assert result.rms_px == summary["approximation_error_px"]["rms"]
    assert result.max_px == summary["approximation_error_px"]["max"]
    assert len(result.pixels) == len(result.points_in_mirror) == len(result.error_px) == summary["samples"]
    assert np.array_equal(result.central_from_mirror, summary["central_from_mirror"])
    assert {k: np.asarray(v).tolist() for k, v in result.parameters.items()} == summary["parameters"]
    assert [row[0] for row in result.error_at_other_distances] == [2, 3, 5, 7, 10, 20, 40, 100, math.inf]
    assert [row[3] for row in result.error_at_other_distances] == [e["max_px"] for e in summary["error_at_other_distances"]]
    errors = np.loadtxt(tmp_path / "cli" / "central_error.csv", delimiter=",", skiprows=1)
    np.testing.assert_allclose(result.omega_deg, errors[:, 2], rtol=5e-10)  # the CSV's 10 digits
    assert np.sqrt(np.mean(result.error_px ** 2)) == pytest.approx(result.rms_px, rel=1e-12)
    if model == "mei":
        assert result.fitted_for == "objects at infinity"
        # The exported model projects the samples' object points that far from their pixels
        # (1e-9 px: the same formula evaluated in another order).
        projected = mei_project(result.parameters, result.central_from_mirror, result.v0_mm, result.points_in_mirror)
        np.testing.assert_allclose(np.linalg.norm(projected - result.pixels, axis=1), result.error_px, atol=1e-9)
        np.testing.assert_allclose(result.pixels, errors[:, :2], rtol=5e-10)
    else:
        assert result.fitted_for.startswith("objects on a sphere of 307.3")


def test_bad_input_gives_the_cli_message(cli, data, tmp_path):
    path = str(data / SPH)
    out = tmp_path / "out"

    def remap_error(*flags):
        return cli_error(cli("remap", "--sensor", path, "--out", out, *flags))

    def raised(call, *args, **kwargs):
        with pytest.raises(omnical.InputError) as error:
            call(*args, **kwargs)
        return str(error.value)

    missing = str(tmp_path / "missing.yaml")
    assert raised(omnical.remap, missing, n=7) == cli_error(
        cli("remap", "--sensor", missing, "--view", "panorama", "--n", 7, "--out", out))
    assert raised(omnical.parallax, missing, n=7) == cli_error(cli("parallax", "--sensor", missing, "--n", 7, "--out", out))
    # Values: the CLI names the flag where Python names the keyword, the rest is the same.
    expected = remap_error("--view", "panorama", "--n", 7, "--size", "12")
    assert expected.startswith("--size: ") and raised(omnical.remap, path, n=7, size="12") == expected[2:]
    expected = remap_error("--view", "panorama", "--n", 0)
    assert raised(omnical.remap, path, n=0) == expected[2:] == "n: the object distance must be > 0"
    expected = remap_error("--view", "perspective", "--tilt-deg=89", "--size", "40x30", "--n", 7)
    assert expected.startswith("--view: no output pixel sees the mirror")
    assert raised(omnical.remap, path, "perspective", tilt_deg=89, size=(40, 30), n=7) == expected[2:]
    expected = cli_error(cli("export-central", "--sensor", path, "--model", "mei", "--n", 0, "--out", out))
    assert raised(omnical.export_central, path, n=0) == expected[2:]
    # Both distances: the CLI's parser refuses the flag pair before the library sees it;
    # Python gets the library's message naming both keywords.
    assert "excludes" in remap_error("--view", "panorama", "--n", 7, "--distance-mm", 300)
    assert raised(omnical.remap, path, n=7, distance_mm=300) == "n: give only one of distance_mm, n and infinity"
    assert raised(omnical.export_central, path, n=7, distance_mm=300) == "n: give only one of distance_mm and n"
    # parallax: the CLI's parser checks --n > 0 itself ("--n: must be > 0 (got 0)").
    assert cli_error(cli("parallax", "--sensor", path, "--n", 0, "--out", out)).startswith("--n: must be > 0")
    assert raised(omnical.parallax, path, n=0) == "n: must be > 0"
    assert raised(omnical.parallax, path) == "distance_mm: give the object distance (distance_mm or n)"
    assert raised(omnical.parallax, path, n=7, samples=5) == "samples: 5 (10..100000)"
    # Names the CLI restricts to a list.
    assert raised(omnical.remap, path, "fisheye", n=7) == "view: unknown view 'fisheye'"
    assert raised(omnical.remap, path, n=7, size=(1, 2, 3)) == "size: expected 'WxH' or (width, height), got (1, 2, 3)"
    assert raised(omnical.remap(path, size=(32, 8), n=7).save, out, formats=("png",)) == \
        "formats: unknown 'png' (opencv, ffmpeg, npy)"
    assert raised(omnical.export_central, path, model="kannala") == "model: unknown 'kannala' (mei, ocamcalib)"
    image = cv2.imread(str(data / IMAGE), cv2.IMREAD_UNCHANGED)
    # A corrupt maps.json: unwarp and parallax --maps say what the CLI says.
    maps = tmp_path / "maps"
    maps.mkdir()
    (maps / "maps.json").write_text("{")
    expected = cli_error(cli("unwarp", "--maps", maps, "--input", data / IMAGE, "--out", tmp_path / "u.png"))
    assert expected.endswith("maps.json: is not valid JSON")
    assert raised(omnical.unwarp, image, str(maps)) == expected
    assert raised(omnical.Unwarper.from_maps, maps) == expected
    assert raised(omnical.maps_error, str(maps)) == cli_error(cli("parallax", "--maps", maps, "--out", out))
    assert raised(omnical.unwarp, image, maps, interpolation="area") == "interpolation: unknown 'area' (nearest, linear, cubic)"
    assert raised(omnical.unwarp, image, (np.zeros((4, 4)), np.zeros((4, 5)))).startswith("maps: expected")
    # The maps' sensor against another of a different image size.
    good = tmp_path / "good"
    omnical.remap(path, size=(32, 8), n=7).save(good)
    other = str(data / MISALIGNED)
    expected = cli_error(cli("unwarp", "--maps", good, "--sensor", other, "--input", data / IMAGE, "--out", tmp_path / "u.png"))
    assert raised(omnical.Unwarper.from_maps, good, sensor=other) == expected
