"""omnical.design_ode, design_fit and characterize against `omnical design ode`,
`omnical design fit` and `omnical characterize`, and against the seed papers' numbers."""
import csv
import json
import math

import numpy as np
import pytest

import omnical
from conftest import cli_error

# The JSON files hold doubles as shortest round-trip text, so the CLI's numbers and the
# library's, computed by the same deterministic code, agree to the last bit; 1e-12 relative
# is the stated bound (a different compiler flag could move the last digits of an ODE).
REL = 1e-12


def close(a, b, rel=REL):
    return math.isclose(a, b, rel_tol=rel, abs_tol=rel * 1e-3)


def assert_same_parameters(a, b, rel):
    """Two sensor parameter dicts: the same keys and strings, numbers to `rel`."""
    if isinstance(a, dict):
        assert sorted(a) == sorted(b)
        for key in a:
            assert_same_parameters(a[key], b[key], rel)
    elif isinstance(a, list):
        assert len(a) == len(b)
        for x, y in zip(a, b):
            assert_same_parameters(x, y, rel)
    elif isinstance(a, (int, float)) and not isinstance(a, bool):
        assert close(a, b, rel), (a, b)
    else:
        assert a == b


def same_files(dir_a, dir_b, names):
    for name in names:
        assert (dir_a / name).read_bytes() == (dir_b / name).read_bytes(), name


def read_csv(path):
    rows = [line for line in path.read_text().splitlines() if not line.startswith("#")]
    return list(csv.reader(rows))


def test_design_ode_equals_cli_and_seed(data, tmp_path, cli):
    spec = data / "designs" / "gaechter-uniform.yaml"
    assert cli("design", "ode", "--spec", spec, "--out", tmp_path / "cli", "--quiet").returncode == 0
    stages = set()
    r = omnical.design_ode(spec, progress=lambda stage, done, total: stages.add(stage))
    assert stages == {"ode", "trace law"}
    j = json.loads((tmp_path / "cli" / "design.json").read_text())
    for key in ("phi0_deg", "phi1_deg", "fov_deg", "max_law_error_rel"):
        assert close(getattr(r, key), j[key]), key
    for key in ("t_start_mm", "t_end_mm", "rho_end_mm"):
        assert close(getattr(r, key), j["field"][key]), key
    assert r.ended_at_rim == j["field"]["ends_at"].startswith("mirror rim")
    assert r.ode_steps == j["ode"]["steps"] and len(r.profile_table) == j["ode"]["profile_samples"] == 20001
    assert close(r.m_mm, j["sensor"]["m_mm"]) and close(r.pixel_pitch_mm, j["sensor"]["pixel_pitch_mm"])
    assert close(r.vertex_height_mm, r.m_mm + 12.5)  # F0 = m + f, f = 12.5 mm in the spec
    sensitivity = j["distance_sensitivity"]
    np.testing.assert_array_equal(r.law_ratio_distance_mm, [s["distance_mm"] for s in sensitivity])
    np.testing.assert_allclose(r.law_ratio.min(axis=1), [s["ratio_min"] for s in sensitivity], rtol=REL)
    np.testing.assert_allclose(r.law_ratio.max(axis=1), [s["ratio_max"] for s in sensitivity], rtol=REL)
    # law_ratio.csv and profile.csv print 12 and 15 significant digits.
    ratio_rows = np.array(read_csv(tmp_path / "cli" / "law_ratio.csv")[1:], dtype=float)
    np.testing.assert_allclose(r.law_ratio_rho_mm, ratio_rows[:, 0], rtol=1e-11)
    np.testing.assert_allclose(r.law_ratio.T, ratio_rows[:, 1:], rtol=1e-11)
    profile_rows = np.array(read_csv(tmp_path / "cli" / "profile.csv")[1:], dtype=float)
    np.testing.assert_allclose(r.profile_table, profile_rows, rtol=1e-14, atol=1e-300)

    # The sensor equals the CLI's sensor.yaml (written with 15 significant digits).
    # The table path: as the sensor names it, and resolved against the file when loaded.
    ours, theirs = r.sensor.parameters, omnical.Sensor.load(tmp_path / "cli" / "sensor.yaml").parameters
    assert ours["mirror"].pop("table") == "profile.csv"
    assert theirs["mirror"].pop("table") == str(tmp_path / "cli" / "profile.csv")
    assert_same_parameters(ours, theirs, 1e-14)
    assert r.sensor.image_size == (1000, 1000) and r.sensor.rim_radius_mm == pytest.approx(r.t_end_mm, rel=1e-14)

    # The seed's uniform design (Gächter Sec. 3.2): the axis ray sees the cylinder at
    # phi0 = atan(d / (F0 - b)) = atan(2000 / 4155) = 25.704 deg; field 80.8 deg to 106.5 deg;
    # the law holds through omnical's own ray tracing within 1e-6.
    assert r.phi0_deg == pytest.approx(math.degrees(math.atan(2000 / (155 + 4000))), abs=0.01)
    assert r.phi0_deg == pytest.approx(25.704, abs=0.01)
    assert r.phi1_deg == pytest.approx(106.5, abs=0.1) and r.fov_deg == pytest.approx(80.8, abs=0.1)
    assert r.max_law_error_rel < 1e-6

    # save() writes the CLI's files byte for byte, figures included.
    r.save(tmp_path / "py")
    names = sorted(p.name for p in (tmp_path / "cli").iterdir())
    assert names == sorted(["design.json", "profile.csv", "sensor.yaml", "law_ratio.csv", "law_ratio.png",
                            "profile.png", "profile_drawing.svg", "profile_drawing.png"])
    assert sorted(p.name for p in (tmp_path / "py").iterdir()) == names
    same_files(tmp_path / "py", tmp_path / "cli", names)

    # The same design from the fields instead of the file (as the CLI's flags).
    by_fields = omnical.design_ode(law="linear", focal_length_mm=12.5, distance_mm=2000, start_height_mm=155,
                                   rim_limit_mm=30, rho1_mm=2.4, gain=2000, offset_mm=-4000, samples=2001,
                                   image_size_px=500)
    assert by_fields.phi1_deg == pytest.approx(r.phi1_deg, abs=1e-9)
    assert len(by_fields.profile_table) == 2001 and by_fields.sensor.image_size == (500, 500)


def test_design_ode_bad_input(data, tmp_path, cli):
    bad = tmp_path / "bad"

    def same_as_cli(cli_args, **kwargs):
        with pytest.raises(omnical.InputError) as error:
            omnical.design_ode(**kwargs)
        assert str(error.value) == cli_error(cli("design", "ode", *cli_args, "--out", bad))
        return str(error.value)

    missing = tmp_path / "none.yaml"
    assert "file not found" in same_as_cli(["--spec", missing], spec=missing)
    typo = tmp_path / "typo.yaml"
    typo.write_text("focal_length_mm: 12.5\ndistance_mm: 2000\nstart_height_mm: 155\nrim_limit_mm: 30\n"
                    "imager: { rho1_mm: 2.4 }\nlaw: { type: cubic }\n")
    assert "law.type" in same_as_cli(["--spec", typo], spec=typo)
    fields = dict(focal_length_mm=12.5, distance_mm=2000, start_height_mm=155, rim_limit_mm=30)
    flags = ["--focal-length-mm", "12.5", "--distance-mm", "2000", "--start-height-mm", "155", "--rim-limit-mm", "30"]
    message = same_as_cli(flags + ["--law", "linear", "--rho1-mm", "3", "--gain", "2000", "--offset-mm", "-4000"],
                          law="linear", rho1_mm=3, gain=2000, offset_mm=-4000, **fields)
    assert "beyond the image of the rim" in message
    bent = tmp_path / "bent.csv"
    bent.write_text("rho_mm,h_mm\n0,-4000\n1,-2000\n2,-2500\n3,2000\n")
    message = same_as_cli(flags + ["--law", "table", "--law-table", bent, "--rho1-mm", "2.4"],
                          law="table", law_table=bent, rho1_mm=2.4, **fields)
    assert "not monotone (h does not increase) at row 3" in message
    # A bad field value: the library names the field (the CLI sets the same field).
    assert same_as_cli(flags + ["--law", "linear", "--rho1-mm", "2.4", "--gain", "-1", "--offset-mm", "0"],
                       law="linear", rho1_mm=2.4, gain=-1, offset_mm=0, **fields) == \
        "design ode: law.gain: must be positive (h must grow with rho)"
    with pytest.raises(omnical.InputError, match=r"^design ode: samples: must be in \[100, 1000000\]$"):
        omnical.design_ode(data / "designs" / "gaechter-uniform.yaml", samples=10)
    with pytest.raises(omnical.InputError, match="^law: must be linear, logpolar or table, not 'cubic'$"):
        omnical.design_ode(law="cubic", **fields)
    with pytest.raises(omnical.InputError, match="not both"):
        omnical.design_ode(data / "designs" / "gaechter-uniform.yaml", gain=3)
    with pytest.raises(omnical.InputError, match="needs law_table"):
        omnical.design_ode(law="table", **fields)
    assert not bad.exists()


def test_design_fit_sphere_equals_cli_and_table1(tmp_path, cli):
    assert cli("design", "fit", "--profile", "sphere", "--rim-omega", "135", "--rim-theta", "12",
               "--out", tmp_path / "cli", "--quiet").returncode == 0
    stages = set()
    r = omnical.design_fit(profile="sphere", rim_omega_deg=135, rim_theta_deg=12,
                           progress=lambda stage, done, total: stages.add(stage))
    assert "measure" in stages
    assert (r.profile, r.characteristic, r.law) == ("sphere", "none", "equidistant")
    # Ohte & Tsuzuki Table 1 (SPH): A = 1.138, m = 4.110; omnical's closed form to 6 digits
    # (docs/design.md); and independently: the rim slope tan(beta) = 1 / sqrt(A^2 - 1) with
    # beta = (Omega - Theta) / 2 gives A = 1 / sin(beta), and m = 1 / tan(Theta) - f(1) (Eq. 5).
    assert r.parameters["A"] == pytest.approx(1.13789, abs=5e-6)
    assert r.parameters["m"] == pytest.approx(4.10969, abs=5e-6)
    beta = math.radians((135 - 12) / 2)
    a = 1 / math.sin(beta)
    assert r.parameters["A"] == pytest.approx(a, rel=1e-12)
    assert r.parameters["m"] == pytest.approx(1 / math.tan(math.radians(12)) - (a - math.sqrt(a * a - 1)), rel=1e-12)
    assert r.achieved.rim_omega_deg == pytest.approx(135, abs=1e-9)
    assert r.achieved.rim_theta_deg == pytest.approx(12, abs=1e-9)
    assert r.free_parameters == 0 and r.solver_report.startswith("closed form") and r.compared is None

    j = json.loads((tmp_path / "cli" / "design.json").read_text())
    assert j["parameters"]["normalised"] == pytest.approx(r.parameters, rel=REL)
    assert j["parameters"]["mm"]["A_mm"] == pytest.approx(r.parameters["A"] * r.rim_radius_mm, rel=REL)
    assert j["parameters"]["mm"]["rim_radius_mm"] == r.rim_radius_mm == 43.9
    for key, value in j["achieved"].items():
        assert close(getattr(r.achieved, key), value), key
    assert (r.iterations, r.final_cost, r.solver_report) == \
        (j["solver"]["iterations"], j["solver"]["final_cost"], j["solver"]["report"])
    rows = np.array(read_csv(tmp_path / "cli" / "characteristic.csv")[1:], dtype=float)
    samples = r.achieved.samples
    for k, key in enumerate(["x_mm", "omega_deg", "h_px"]):
        np.testing.assert_allclose(samples[key], rows[:, k], rtol=1e-11, atol=1e-12)  # 12 digits
    np.testing.assert_allclose(samples["viewpoint_z_mm"], rows[:, 4], rtol=1e-11)
    np.testing.assert_allclose(r.profile_table, np.array(read_csv(tmp_path / "cli" / "profile.csv")[1:], dtype=float),
                               rtol=1e-14, atol=1e-300)
    assert_same_parameters(r.sensor.parameters, omnical.Sensor.load(tmp_path / "cli" / "sensor.yaml").parameters, 0)

    r.save(tmp_path / "py")
    names = sorted(p.name for p in (tmp_path / "cli").iterdir())
    assert len(names) == 7 and sorted(p.name for p in (tmp_path / "py").iterdir()) == names
    same_files(tmp_path / "py", tmp_path / "cli", names)


def test_design_fit_polynomial_compared(data, tmp_path, cli):
    table1 = data / "sensors" / "ohte-edi.yaml"
    assert cli("design", "fit", "--profile", "polynomial", "--compare", table1, "--out", tmp_path / "cli",
               "--quiet").returncode == 0
    r = omnical.design_fit(profile="polynomial", compare=table1)
    j = json.loads((tmp_path / "cli" / "design.json").read_text())
    assert r.characteristic == "equidistant" and sorted(r.parameters) == ["c1", "c2", "c3", "m"]
    assert j["parameters"]["normalised"] == pytest.approx(r.parameters, rel=REL)
    assert j["compared"]["file"] == str(table1)
    for key in ("equidistant_max_px", "rim_h_px", "viewpoint_spread_mm"):
        assert close(getattr(r.compared, key), j["compared"][key]) and close(getattr(r.achieved, key), j["achieved"][key])
    # The fitted polynomial is more linear than Table 1's printed coefficients.
    assert r.achieved.equidistant_max_px < r.compared.equidistant_max_px
    assert r.free_parameters == 2 and r.iterations > 0
    # A Sensor object compares the same.
    same = omnical.design_fit(profile="polynomial", compare=omnical.Sensor.load(table1))
    assert same.compared.equidistant_max_px == r.compared.equidistant_max_px


def test_design_fit_bad_input(data, tmp_path, cli):
    bad = tmp_path / "bad"
    # A bad value: the CLI names its flags where Python names the kwargs (the fields).
    with pytest.raises(omnical.InputError) as error:
        omnical.design_fit(profile="sphere", rim_omega_deg=10)
    expected = cli_error(cli("design", "fit", "--profile", "sphere", "--rim-omega", "10", "--out", bad))
    assert "--rim-omega" in expected
    assert str(error.value) == expected.replace("--rim-omega", "rim_omega_deg").replace("--rim-theta", "rim_theta_deg")
    assert str(error.value).startswith("design fit: rim_omega_deg: must lie between rim_theta_deg and 180 deg")
    # A sphere has no freedom left for a characteristic: the library's text, as the CLI's.
    with pytest.raises(omnical.InputError) as error:
        omnical.design_fit(profile="sphere", characteristic="equidistant")
    assert str(error.value) == cli_error(
        cli("design", "fit", "--profile", "sphere", "--characteristic", "equidistant", "--out", bad))
    missing = tmp_path / "none.yaml"
    with pytest.raises(omnical.InputError) as error:
        omnical.design_fit(profile="polynomial", compare=missing)
    assert str(error.value) == cli_error(cli("design", "fit", "--profile", "polynomial", "--compare", missing,
                                             "--out", bad))
    tilted = data / "sensors" / "ohte-sph-misaligned.yaml"
    with pytest.raises(omnical.InputError) as error:
        omnical.design_fit(profile="polynomial", compare=tilted)
    assert "tilted or decentred" in str(error.value)
    assert str(error.value) == cli_error(cli("design", "fit", "--profile", "polynomial", "--compare", tilted,
                                             "--out", bad))
    with pytest.raises(omnical.InputError, match="^profile: must be sphere, polynomial, hyperboloid, paraboloid or even_asphere, not 'cone'$"):
        omnical.design_fit(profile="cone")
    with pytest.raises(omnical.InputError, match="^characteristic: must be none, equidistant, svp, aspect or area"):
        omnical.design_fit(profile="polynomial", characteristic="linear")
    with pytest.raises(omnical.Cancelled):
        omnical.design_fit(profile="polynomial", progress=lambda stage, done, total: stage != "fit")
    assert not bad.exists()


def test_characterize_equals_cli(data, tmp_path, cli):
    sensor_file = data / "sensors" / "ohte-sph.yaml"
    assert cli("characterize", "--sensor", sensor_file, "--out", tmp_path / "cli", "--samples", "120",
               "--quiet").returncode == 0
    stages = set()
    r = omnical.characterize(sensor_file, samples=120, progress=lambda stage, done, total: stages.add(stage))
    assert {"field", "focus"} <= stages
    rows = read_csv(tmp_path / "cli" / "characteristics.csv")
    header, rows = rows[0], rows[1:]
    assert list(r.curves) == header and len(rows) == r.samples == 120
    # The CSV prints 10 significant digits (C++ setprecision(10) = printf %.10g): the arrays
    # formatted the same way give the CSV's text exactly.
    for k, name in enumerate(header):
        assert ["%.10g" % v for v in r.curves[name]] == [row[k] for row in rows], name
    summary = json.loads((tmp_path / "cli" / "summary.json").read_text())
    assert (r.profile, r.lens, r.axial) == (summary["profile"], summary["lens"], summary["analysed_as"] == "axial")
    pairs = {"best_L0_mm": r.focus_mm, "viewpoint_spread_mm": r.viewpoint_spread_mm, "rim_omega_deg": r.rim_omega_deg,
             "rim_theta_deg": r.rim_theta_deg, "max_astigmatism_mm": r.max_astigmatism_mm,
             "lens_focal_mm": r.lens_focal_mm, "f_number": r.f_number, "pixel_um": r.pixel_um,
             "near_distance_mm": r.near_distance_mm, "mean_blur_area_deg2": r.mean_blur_area_deg2,
             "worst_blur_px": r.worst_blur_px,
             "mean_solid_angle_per_pixel_deg2": r.mean_solid_angle_per_pixel_deg2}
    for key, value in pairs.items():
        assert close(value, summary[key]), key
    # null: beyond the hyperfocal distance (infinite).
    assert summary["depth_of_field_mm"] is None and math.isinf(r.depth_of_field_mm) or \
        close(r.depth_of_field_mm, summary["depth_of_field_mm"])
    assert summary["viewpoint_range_mm"] == pytest.approx([r.viewpoint_min_mm, r.viewpoint_max_mm], rel=REL)
    assert summary["caustic_extent_mm"] == pytest.approx({"radial": r.caustic_radial_mm, "axial": r.caustic_axial_mm},
                                                         rel=REL)
    assert summary["dh_domega_px_per_deg"]["min"] == pytest.approx(r.dh_domega_min, rel=REL)
    assert summary["dh_domega_px_per_deg"]["max"] == pytest.approx(r.dh_domega_max, rel=REL)
    assert r.focus_searched and r.azimuth_curves == [] and r.rim_radius_mm == 43.9 and r.m_mm == 180.429
    # The seed's sphere (Table 1): the rim ray at Omega 135 deg, Theta 12 deg (4 printed digits).
    assert r.rim_omega_deg == pytest.approx(135, abs=0.05) and r.rim_theta_deg == pytest.approx(12, abs=0.05)

    r.save(tmp_path / "py")
    names = sorted(p.name for p in (tmp_path / "cli").iterdir())
    assert len(names) == 8 and sorted(p.name for p in (tmp_path / "py").iterdir()) == names
    same_files(tmp_path / "py", tmp_path / "cli", names)

    # A Sensor object and given lens settings; a tilted sensor has azimuth curves.
    fixed = omnical.characterize(omnical.Sensor.load(sensor_file), samples=30, focus_mm=250, lens_focal_mm=8)
    assert not fixed.focus_searched and fixed.focus_mm == 250 and fixed.lens_focal_mm == 8
    tilted = omnical.characterize(data / "sensors" / "ohte-sph-misaligned.yaml", samples=30)
    assert not tilted.axial and len(tilted.azimuth_curves) == 4 and tilted.azimuth_curves[0].shape[1] == 3


def test_characterize_bad_input(data, tmp_path, cli):
    bad = tmp_path / "bad"
    # The rim outside the image: the library's "sensor: ..." named by the file, as the CLI.
    parameters = omnical.Sensor.load(data / "sensors" / "ohte-sph.yaml").parameters
    parameters["camera"].update(image_size=[600, 600], cx=299.5, cy=299.5)
    small = tmp_path / "small.yaml"
    omnical.Sensor.from_parameters(parameters).save(small)
    with pytest.raises(omnical.InputError) as error:
        omnical.characterize(small)
    assert str(error.value).startswith(str(small) + ": ")
    assert str(error.value) == cli_error(cli("characterize", "--sensor", small, "--out", bad))
    missing = tmp_path / "none.yaml"
    with pytest.raises(omnical.InputError) as error:
        omnical.characterize(missing)
    assert str(error.value) == cli_error(cli("characterize", "--sensor", missing, "--out", bad))
    # Bad values: the library's field names are the kwargs (the CLI's validators name flags).
    sensor = omnical.Sensor.load(data / "sensors" / "ohte-sph.yaml")
    with pytest.raises(omnical.InputError, match=r"^f_number: must be > 0$"):
        omnical.characterize(sensor, f_number=-1)
    with pytest.raises(omnical.InputError, match=r"^samples: must be in \[10, 100000\]$"):
        omnical.characterize(sensor, samples=5)
    expected = cli_error(cli("characterize", "--sensor", data / "sensors" / "ohte-sph.yaml", "--out", bad,
                             "--f-number", "-1"))
    assert expected.startswith("--f-number: must be > 0")
    assert not bad.exists()
