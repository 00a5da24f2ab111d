"""omnical.Scene, omnical.render and omnical.save_rendered against `omnical render` and
against independent geometry. A tiny scene (160 x 160 px, 4 samples per pixel, two views)
keeps the renders to well under a second."""
import json
import math

import cv2
import numpy as np
import pytest

import omnical
from conftest import cli_error

# The seed's spherical mirror (datasets-synthetic/sensors/ohte-sph.yaml) on a 160 px image:
# fx scaled by 160 / 1000 so the rim still fills the image.
SCENE = """\
sensor:
  camera: {{ model: pinhole, image_size: [160, 160], fx: 376.38563773336443, fy: 376.38563773336443, cx: 79.5, cy: 79.5, k1: 0, k2: 0, body_radius_mm: 15 }}
  mirror: {{ profile: sphere, rim_radius: 43.9, A: 49.95819999999999 }}
  pose:   {{ m: 180.429, tilt_deg: [0, 0], decenter_mm: [0, 0] }}
render: {{ samples_per_pixel: 4, noise_sigma: 2, vignetting: 0.15, seed: 3 }}
environment: {{ type: room, half_size_mm: 2500, tile_mm: 250, levels: [0.25, 0.55] }}
targets:
  board: {target}
views:
  - {{ name: front, board: {{ omega_deg: 70, azimuth_deg: 0, distance_n: 6, tilt_deg: [10, -5] }} }}
  - {{ name: side, board: {{ omega_deg: 90, azimuth_deg: 120, distance_n: 7, roll_deg: 20 }} }}
"""

TAG_MM, SPACING, COLS, ROWS = 30.0, 0.3, 6, 6  # datasets-synthetic/targets/aprilgrid-6x6-30mm.yaml


@pytest.fixture
def scene_file(tmp_path, data):
    path = tmp_path / "tiny.yaml"
    path.write_text(SCENE.format(target=data / "targets" / "aprilgrid-6x6-30mm.yaml"))
    return path


def aprilgrid_corners():
    """Corner id -> board point (mm), from the layout calib/target.h documents (Kalibr's):
    tag t = row * cols + col, its black square's bottom-left corner at pitch * (col, row),
    corners 4 t + k counter-clockwise from the bottom-left."""
    pitch = TAG_MM * (1.0 + SPACING)
    corners = {}
    for row in range(ROWS):
        for col in range(COLS):
            x, y, tag = col * pitch, row * pitch, row * COLS + col
            for k, (dx, dy) in enumerate([(0, 0), (1, 0), (1, 1), (0, 1)]):
                corners[4 * tag + k] = (x + dx * TAG_MM, y + dy * TAG_MM, 0.0)
    return corners


def test_scene_properties(scene_file):
    scene = omnical.Scene.load(scene_file)
    assert len(scene) == 2 and scene.view_names == ["front", "side"]
    assert repr(scene) == f"<omnical.Scene {scene_file}: 2 views, 160x160 px>"
    assert scene.path == str(scene_file)
    assert scene.sensor.image_size == (160, 160) and scene.sensor.profile == "sphere"
    assert scene.formation == {"samples_per_pixel": 4, "noise_sigma": 2.0, "blur_sigma_px": 0.0,
                               "vignetting": 0.15, "seed": 3}
    view = scene.views[0]
    assert view.name == "front" and [t.name for t in view.targets] == ["board"]
    target = view.targets[0]
    assert target.spec_path.endswith("aprilgrid-6x6-30mm.yaml")
    independent = aprilgrid_corners()
    assert sorted(target.corner_ids.tolist()) == sorted(independent)
    expected = np.array([independent[i] for i in target.corner_ids])
    np.testing.assert_allclose(target.corner_points_mm, expected, rtol=0, atol=1e-12)  # mm, exact layout
    pose = target.camera_from_target
    assert pose.shape == (4, 4)
    np.testing.assert_allclose(pose[:3, :3] @ pose[:3, :3].T, np.eye(3), atol=1e-12)  # a rotation
    np.testing.assert_array_equal(pose[3], [0, 0, 0, 1])
    # The board centre is 6 mirror radii from the vertex (the scene's distance_n), the
    # vertex m = 180.429 mm from the lens along z.
    centre = pose[:3, :3] @ np.array([3.0 * TAG_MM * (1 + SPACING) - 0.5 * TAG_MM * SPACING] * 2 + [0]) + pose[:3, 3]
    assert abs(np.linalg.norm(centre - [0, 0, 180.429]) - 6 * 43.9) < 1e-6


def test_render_equals_cli_and_geometry(scene_file, tmp_path, cli):
    completed = cli("render", "--scene", scene_file, "--out", tmp_path / "cli", "--quiet")
    assert completed.returncode == 0, completed.stderr
    scene = omnical.Scene.load(scene_file)
    calls = []
    views = omnical.render(scene, threads=2, progress=lambda stage, done, total: calls.append((stage, done, total)))
    assert [v.name for v in views] == ["front", "side"]
    assert ("render front (1/2)", 160, 160) in calls and ("render side (2/2)", 160, 160) in calls

    for view in views:
        # Bit for bit the CLI's PNG (same scene, noise seeded per view, any thread count).
        png = cv2.imread(str(tmp_path / "cli" / f"{view.name}.png"), cv2.IMREAD_UNCHANGED)
        assert view.image.dtype == np.uint8 and view.image.shape == (160, 160)
        assert not view.image.flags.writeable
        np.testing.assert_array_equal(view.image, png)
        truth_file = json.loads((tmp_path / "cli" / f"{view.name}.json").read_text())
        assert len(view.targets) == len(truth_file["targets"]) == 1
        truth, expected = view.targets[0], truth_file["targets"][0]
        assert (truth.name, truth.type) == (expected["name"], expected["type"])
        assert truth.spec_path == scene.views[0].targets[0].spec_path
        corners = expected["corners"]
        np.testing.assert_array_equal(truth.ids, [c["id"] for c in corners])
        # The JSON holds doubles as shortest round-trip text: equal to the last bit.
        np.testing.assert_array_equal(truth.target_mm, [c["target_mm"] for c in corners])
        np.testing.assert_array_equal(truth.camera_mm, [c["camera_mm"] for c in corners])
        np.testing.assert_array_equal(truth.pixels, [c["pixel"] or [math.nan, math.nan] for c in corners])
        np.testing.assert_array_equal(truth.visible, [c["visible"] for c in corners])
        assert [omnical.status_name(s) for s in truth.status] == [c["status"] for c in corners]
        pose = expected["camera_from_target"]
        np.testing.assert_array_equal(truth.camera_from_target[:3, :3], pose["rotation"])
        np.testing.assert_array_equal(truth.camera_from_target[:3, 3], pose["translation_mm"])
        assert truth.visible.sum() == expected["visible_corners"] > 20

        # Independently: the board points from the documented aprilgrid layout, moved by the
        # pose and projected through the sensor's batch path, land on the truth's pixels
        # (1e-9 px: the same exact projection, computed a second way).
        layout = aprilgrid_corners()
        board = np.array([layout[i] for i in truth.ids])
        np.testing.assert_allclose(truth.target_mm, board, rtol=0, atol=1e-12)
        homogeneous = np.c_[board, np.ones(len(board))]
        in_camera = (truth.camera_from_target @ homogeneous.T).T[:, :3]
        np.testing.assert_allclose(in_camera, truth.camera_mm, rtol=0, atol=1e-9)  # mm
        pixels, status = scene.sensor.project(in_camera)
        np.testing.assert_array_equal(status, truth.status)
        ok = status == omnical.ProjectionStatus.OK
        assert ok[truth.visible].all()
        assert np.abs(pixels[ok] - truth.pixels[ok]).max() < 1e-9

    # save_rendered writes the CLI's files byte for byte (spec and scene paths relative to
    # the output directory, so both directories side by side read the same).
    omnical.save_rendered(scene, views, tmp_path / "py", scene_path=str(scene_file))
    names = sorted(p.name for p in (tmp_path / "cli").iterdir())
    assert names == ["front.json", "front.png", "scene.json", "sensor.yaml", "side.json", "side.png"]
    assert sorted(p.name for p in (tmp_path / "py").iterdir()) == names
    for name in names:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    # The default scene_path is the file the scene was loaded from.
    omnical.save_rendered(scene, views[:1], tmp_path / "py1")
    assert json.loads((tmp_path / "py1" / "scene.json").read_text())["scene"] == "../tiny.yaml"


def test_render_cancel_and_bad_input(scene_file, tmp_path, cli):
    scene = omnical.Scene.load(scene_file)
    with pytest.raises(omnical.Cancelled):
        omnical.render(scene, progress=lambda stage, done, total: False)
    # A bad option value: the library's message names the kwarg (the field).
    with pytest.raises(omnical.InputError, match=r"^threads: must be >= 1 \(got -1\)$"):
        omnical.render(scene, threads=-1)
    # Views of another scene object are refused.
    other = omnical.Scene.load(scene_file)
    views = omnical.render(other, threads=1)
    with pytest.raises(omnical.InputError, match="not rendered from this scene"):
        omnical.save_rendered(scene, views, tmp_path / "x")
    assert not (tmp_path / "x").exists()

    # A missing scene file and a corrupt one: the CLI's message, word for word.
    missing = tmp_path / "none.yaml"
    with pytest.raises(omnical.InputError) as error:
        omnical.Scene.load(missing)
    assert str(error.value) == cli_error(cli("render", "--scene", missing, "--out", tmp_path / "bad"))
    corrupt = tmp_path / "corrupt.yaml"
    corrupt.write_text(scene_file.read_text().replace("omega_deg: 70", "omega_degs: 70"))
    with pytest.raises(omnical.InputError) as error:
        omnical.Scene.load(corrupt)
    assert "omega_degs" in str(error.value)
    assert str(error.value) == cli_error(cli("render", "--scene", corrupt, "--out", tmp_path / "bad"))
    assert not (tmp_path / "bad").exists()

    # No scene (None reached the renderer as a null pointer: a segfault) and view names that
    # would write outside --out, overwrite scene.json or each other.
    with pytest.raises(TypeError, match="scene: expected an omnical.Scene, got None"):
        omnical.render(None)
    with pytest.raises(TypeError, match="got None"):
        omnical.save_rendered(None, [], tmp_path / "x")
    for name, message in [("../escape", "views\\[0\\].name: '../escape': must be"), ("scene", "overwrite scene.json"),
                          ("side", "two views are named 'side'")]:
        renamed = tmp_path / "renamed.yaml"
        renamed.write_text(scene_file.read_text().replace("name: front", "name: " + name))
        with pytest.raises(omnical.InputError, match=message):
            omnical.Scene.load(renamed)
        assert cli_error(cli("render", "--scene", renamed, "--out", tmp_path / "bad")).startswith(str(renamed))
    assert not (tmp_path / "bad").exists() and not (tmp_path / "escape.png").exists()
