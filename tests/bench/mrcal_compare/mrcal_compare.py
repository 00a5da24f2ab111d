#!/usr/bin/python3
"""omnical against mrcal 2.2 on the same corners; writes docs/calibration-vs-mrcal.md.

Per dataset: omnical detects the corners (`calibrate --images`, detections.json); both
tools calibrate from exactly those corners. mrcal fits LENSMODEL_SPLINED_STEREOGRAPHIC
(10 and 16 knots across) seeded as mrcal-calibrate-cameras seeds it (mrcal_fit.py);
omnical its non-central model through the CLI (`calibrate --detections`, `--holdout K`,
`--cross-validate`). Reported per fit: RMS per corner over all corners and over
inliers, the outlier count, the held-out RMS (K views left out, their poses fitted with
the intrinsics held: BabelCalib's protocol; mrcal holds out the views omnical names)
and the two-halves difference (even- and odd-index views calibrated apart, compared
at 2 m over the observed field).

Usage:
  /usr/bin/python3 tests/bench/mrcal_compare/mrcal_compare.py --omnical build/test/tools/omnical \\
      --out docs/calibration-vs-mrcal.md [--quick] [--checkerboard-subpixel] [--work DIR]
--quick: the real set and the 10-knot model only (the CTest test, < 60 s).
--extra NAME=TARGET.yaml:IMAGE_DIR (repeatable): one more real set, calibrated without a
guess as a new user would (your own images; with --datasets NAME to run only those).
--checkerboard-subpixel: the checkerboard sets' corners from `calibrate --images
--checkerboard-subpixel` (cornerSubPix, the default before edges; both tools then fit
those). Exit 77
(CTest's SKIP_RETURN_CODE) when mrcal does not import or the real-data folder is absent.
Environment: PYTHONPATH with omnical's Python module (build/test/python) when present;
without it the all-corner residuals go through `omnical project`.
"""
import argparse
import math
import os
import re
import shutil
import sys
import tempfile
import time

sys.dont_write_bytecode = True  # no __pycache__ beside the sources
HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
sys.path.insert(0, HERE)

SKIP = 77
DISTANCE_MM = 2000.0
HOLDOUT_VIEWS = 2
KNOTS = (10, 16)
COMMAND = ("/usr/bin/python3 tests/bench/mrcal_compare/mrcal_compare.py "
           "--omnical build/test/tools/omnical --out docs/calibration-vs-mrcal.md")

DEFINITIONS = [
    "- **RMS** (both tools, computed here from each fit's geometry): per corner, sqrt(mean over corners of "
    "|e|²), e the 2-D reprojection error in px. *All*: every corner the fit was given (omnical's outliers "
    "projected through its fitted sensor, poses and board warp; the figure is calibrate's `rms_all_px`); *inliers*: the corners the tool kept. omnical's `rms_px` "
    "is the inlier figure.",
    "- **mrcal's own figure**, `rms_reproj_error__pixels` (what mrcal-calibrate-cameras prints), is "
    "sqrt(‖x‖² / Nmeasurements) over the solver's measurement vector (mrcal.c v2.2, end of `mrcal_optimize`): "
    "*per coordinate* (two measurements per corner), outliers and unobserved grid points counted as zeros, the "
    "regularization terms included. It is not comparable with the RMS columns: about RMS / √2 on a clean fit, "
    "lower still with padding (the aprilgrid's 76 x 76 grid makes it tiny).",
    "- **Outliers**: omnical cuts corners beyond 5σ of the σ of the residuals' bulk (those within 8 median-based "
    "σ; [calibrate](calibrate.md)); mrcal's "
    "default rejection (`markOutliers` in mrcal.c) re-solves while any coordinate residual exceeds 5σ of the "
    "inliers' per-coordinate σ, cutting everything beyond 4σ each time. mrcal's `Noutliers` also counts the "
    "grid points without a corner; the column counts only observed corners it cut.",
    f"- **Held out** (BabelCalib's protocol): {HOLDOUT_VIEWS} views, spread evenly over the set and named by "
    "omnical's `--holdout`, are left out of the calibration; then each held-out board's pose is fitted with the "
    "intrinsics held (mrcal: its board warp too; `mrcal.optimize` with only the frames free, no outlier "
    "rejection) and the RMS is over all held-out corners (omnical's `holdout.rms_px`, same definition).",
    f"- **Halves**: the views at even and at odd positions (omnical's `--cross-validate` names them) calibrated "
    f"apart, each by the tool's full pipeline; points {DISTANCE_MM / 1000:g} m along each observed pixel's ray "
    "through half 1 are moved by the rigid motion that best aligns the two and projected through half 2 "
    "(omnical: `cross_validation`; mrcal: `mrcal.projection_diff` with the implied transform fitted by "
    "`implied_Rt10__from_unprojections` over the observed field: its default focus, a disc at the imager "
    "centre, is the camera's own reflection here). Observed field: the annulus of radii the corners cover "
    "around the projection centre, all round, on a 16 px grid. The mrcal details add the same figure over "
    "the grid points within 24 px of a corner of each half (both calibrations have data there; aligned over "
    "those points): what is left when neither model extrapolates. The per-dataset lines add the halves with one "
    "rigid motion fitted over the field at the boards' median distance and applied at "
    f"{DISTANCE_MM / 1000:g} m (omnical: `cross_validation.aligned_at_boards`, as its predicted error is taken; "
    "mrcal: the implied transform fitted at that distance): fitted at the compared distance itself, the "
    "alignment's translation grows with the distance and takes up a zoom-like disagreement no pose could absorb.",
    "- **mrcal's solve** follows mrcal-calibrate-cameras v2.2 (`solve_initial` and the final solve; "
    "`tests/bench/mrcal_compare/mrcal_fit.py`): a LENSMODEL_STEREOGRAPHIC seed (a central paraboloid is exactly "
    "stereographic, and this field passes 90 deg off the axis, which a pinhole or OpenCV model cannot hold), "
    "geometry-only then core, without outlier rejection or regularization; then the splined model with that "
    "core held, its spline values seeded at ±1e-6, outlier rejection and regularization on; then the final "
    "solve with `calobject_warp` free from (0, 0). Two departures, both measured: board poses are seeded by "
    "PnP through a virtual pinhole turned to each board (`mrcal.seed_stereographic` reprojects the whole field "
    "to one pinhole, which fails past 90 deg); and the core keeps its centre at the imager centre (where "
    "mrcal's seed puts it) with fx = fy, its focal searched, because the free core of mrcal-calibrate-cameras "
    "runs away on the sphere renders (details table: its centre far from the mirror's, fx ≠ fy) and the "
    "splined fits from it were worse there held out and between halves (on the real set the two cores gave "
    "mixed results, within a factor 1.4 of each other on those columns, when this bench was written). `fov_x_deg` = twice the largest corner angle + 20 deg, rounded "
    "up to 10; square knot grids (the mirror's image is a disc).",
    "- **Aprilgrid in mrcal**: mrcal's board is a regular grid at one spacing; the tag corners (30 mm tags, "
    "39 mm pitch) lie on a 3 mm grid of 76 x 76 points, the rest marked missing (weight -1).",
    "- **Time**: one run on this machine; omnical's is the CLI's wall time for `calibrate --detections` "
    "(with its covariance and report), mrcal's the Python solves of the full-set fit (core search + splined).",
]


class Dataset:
    def __init__(self, name, label, target, images, guess=None):
        self.name, self.label, self.target, self.images, self.guess = name, label, target, images, guess
        self.detect_options = []  # extra `calibrate --images` options for the corners both tools fit


def datasets(real_dir):
    synthetic = os.path.join(ROOT, "datasets-synthetic")
    return [
        Dataset("mei-parabolic", "real paracatadioptric images (10), 8 x 6 checkerboard, 42 mm",
                os.path.join(ROOT, "tests/data/mei-parabolic-checkerboard.yaml"), real_dir),
        Dataset("ohte-sph-checkerboard-near", "renders, sphere mirror (6), 8 x 6 checkerboard, 30 mm",
                os.path.join(synthetic, "targets/checkerboard-8x6-30mm.yaml"),
                os.path.join(synthetic, "rendered/ohte-sph-checkerboard-near"),
                os.path.join(synthetic, "sensors/ohte-sph.yaml")),
        Dataset("ohte-sph-misaligned-near", "renders, misaligned sphere (8), 6 x 6 aprilgrid, 30 mm",
                os.path.join(synthetic, "targets/aprilgrid-6x6-30mm.yaml"),
                os.path.join(synthetic, "rendered/ohte-sph-misaligned-near"),
                os.path.join(synthetic, "sensors/ohte-sph-misaligned-guess.yaml")),
    ]


def extra_dataset(spec):
    """--extra NAME=TARGET.yaml:IMAGE_DIR: a set of the user's own, without a guess."""
    name, _, paths = spec.partition("=")
    target, _, images = paths.partition(":")
    if not name or not target or not images:
        raise BenchError(f"--extra '{spec}': expected NAME=TARGET.yaml:IMAGE_DIR")
    for path in (target, images):
        if not os.path.exists(path):
            raise BenchError(f"--extra {name}: {path}: not found")
    count = len([f for f in os.listdir(images) if os.path.isfile(os.path.join(images, f))])
    return Dataset(name, f"{count} images in {os.path.basename(os.path.abspath(images))}, {os.path.basename(target)}",
                   os.path.abspath(target), os.path.abspath(images))


def evenly_spaced(count, k):
    """K indices spread over 0..count-1 (the fallback until omnical names its held-out views)."""
    return sorted({min(count - 1, int((i + 0.5) * count / k)) for i in range(k)})


def index_of(names, wanted):
    """Indices of `wanted` image names in `names` (exact, else by file name)."""
    out = []
    for name in wanted:
        if name in names:
            out.append(names.index(name))
            continue
        base = [i for i, n in enumerate(names) if os.path.basename(n) == os.path.basename(name)]
        if len(base) != 1:
            raise BenchError(f"omnical names view '{name}', which is not among the fitted views")
        out.append(base[0])
    return out


def free_parameters(calibration):
    return sum(1 for p in calibration.get("parameters", {}).values() if not p.get("fixed", False))


def sensor_label(sensor_path):
    text = open(sensor_path).read()
    profile = re.search(r"profile:\s*([A-Za-z_]+)", text)
    lens = re.search(r"model:\s*([A-Za-z_]+)", text)
    return f"{profile.group(1) if profile else '?'} mirror, {lens.group(1) if lens else '?'} lens"


# ---------------------------------------------------------------------------- one dataset

def omnical_side(dataset, cli, out, log):
    """omnical's corners and its fits: full set, --holdout, --cross-validate (or diff)."""
    from omnical_runs import Board, omnical_corner_residuals, read_detections, write_detections
    import residual_structure
    import numpy as np

    log(f"{dataset.name}: omnical detects (calibrate --images)")
    cli.calibrate(dataset.target, os.path.join(out, "images"), images=dataset.images, guess=dataset.guess,
                  extra=dataset.detect_options)
    detections = os.path.join(out, "images", "detections.json")
    data, image_size, all_views = read_detections(detections)

    # The board's warp fitted as mrcal fits calobject_warp: both tools model the same board.
    warp = ["--board-warp"] if cli.has_board_warp else []

    def fit(name, extra=(), corners=detections):
        return cli.calibrate(dataset.target, os.path.join(out, name), detections=corners, guess=dataset.guess,
                             extra=warp + list(extra))

    log(f"{dataset.name}: omnical calibrate --detections")
    full = fit("full")
    views = [v for v in all_views if v["image"] in full["poses"]]  # the views omnical's fit kept
    names = [v["image"] for v in views]
    board = Board(dataset.target)
    residuals, view_of, observed_px, board_xy = omnical_corner_residuals(cli, full, board, views)
    errors = np.linalg.norm(residuals, axis=1)
    finite = errors[np.isfinite(errors)]
    row = dict(tool="omnical", model=f"non-central: {sensor_label(os.path.join(full['_dir'], 'sensor.yaml'))}",
               params=free_parameters(full), corners=int(full.get("observations", finite.size)), views=len(views),
               rms_all_px=float(np.sqrt(np.mean(finite ** 2))) if finite.size else math.nan,
               rms_inliers_px=float(full["rms_px"]), outliers=int(full.get("outliers", 0)),
               unprojected=int(errors.size - finite.size), seconds=full["_seconds"], holdout=None, halves=None,
               board_mm=(float(full["target_distance_mm"]["nearest"]), float(full["target_distance_mm"]["farthest"])))
    # What a more flexible model could still learn from these residuals (residual_structure.py).
    projected = np.all(np.isfinite(residuals), axis=1)
    correlation, pairs = residual_structure.neighbour_correlation(residuals[projected], view_of[projected],
                                                                  board_xy[projected])
    row["structure"] = dict(neighbour_correlation=correlation, neighbour_pairs=pairs,
                            field=residual_structure.correction_field(observed_px[projected], residuals[projected],
                                                                      view_of[projected]))

    held = evenly_spaced(len(views), HOLDOUT_VIEWS)
    if cli.has_holdout:
        log(f"{dataset.name}: omnical calibrate --holdout {HOLDOUT_VIEWS}")
        holdout = fit("holdout", ["--holdout", str(HOLDOUT_VIEWS)]).get("holdout")
        if not holdout:
            raise BenchError(f"{os.path.join(out, 'holdout', 'calibration.json')}: no \"holdout\" key")
        held = sorted(index_of(names, holdout["views"]))
        per_view = {os.path.basename(k): v for k, v in holdout.get("per_view_rms_px", {}).items()}
        row["holdout"] = dict(rms_px=float(holdout["rms_px"]),
                              per_view_px=[per_view.get(os.path.basename(names[i])) for i in held])

    halves = [list(range(0, len(views), 2)), list(range(1, len(views), 2))]
    if cli.has_cross_validate:
        log(f"{dataset.name}: omnical calibrate --cross-validate ({DISTANCE_MM:g} mm)")
        flag = "--cross-validate-distance-mm" if cli.has_cross_validate_distance else "--distance-mm"
        cross = fit("cross", ["--cross-validate", flag, f"{DISTANCE_MM:g}"]).get("cross_validation")
        if not cross:
            raise BenchError(f"{os.path.join(out, 'cross', 'calibration.json')}: no \"cross_validation\" key")
        halves = [sorted(index_of(names, half)) for half in cross["halves"]]
        row["halves"] = dict(diff_rms_px=float(cross["diff_rms_px"]), diff_max_px=float(cross["diff_max_px"]),
                             half_rms_px=[float(v) for v in cross.get("half_rms_px", [])])
        if cross.get("aligned_at_boards"):  # omnical after 2026-11-29: one alignment fitted at the boards
            boards = cross["aligned_at_boards"]
            row["halves"].update(boards_diff_rms_px=float(boards["diff_rms_px"]),
                                 boards_diff_max_px=float(boards["diff_max_px"]),
                                 boards_mm=float(boards["aligned_at_mm"]))
    elif cli.has_diff:
        log(f"{dataset.name}: omnical calibrate per half, omnical diff")
        fits = []
        for h, half in enumerate(halves):
            subset = os.path.join(out, f"half{h}.json")
            write_detections(data, {names[i] for i in half}, subset)
            fits.append(fit(f"half{h}", corners=subset))
        row["halves"] = dict(cli.diff(fits[0]["_dir"], fits[1]["_dir"], DISTANCE_MM, detections,
                                      os.path.join(out, "diff")),
                             half_rms_px=[float(f["rms_px"]) for f in fits])
    return dict(row=row, views=views, names=names, board=board, image_size=image_size, held=held, halves=halves)


def mrcal_side(dataset, omni, knots, log):
    """mrcal on omnical's corners: full set, held-out views, halves, per knot count."""
    import numpy as np
    import mrcal_fit
    import residual_structure

    board, size = omni["board"], omni["image_size"]
    observed = board.observations(omni["views"])
    spacing_m = board.spacing_mm / 1000.0
    start = time.perf_counter()
    core = mrcal_fit.stereographic_core(observed, size, spacing_m)
    core_seconds = time.perf_counter() - start
    free_core = mrcal_fit.free_stereographic_core(observed, size, spacing_m)["problem"]["intrinsics"][0]
    theta = mrcal_fit.field_theta_deg(core["problem"], observed)
    fov_deg = int(min(350, 10 * math.ceil((2 * theta + 20) / 10)))
    centre = core["problem"]["intrinsics"][0][2:4]
    seen = observed[..., 2] > 0
    radius = np.hypot(observed[..., 0] - centre[0], observed[..., 1] - centre[1])[seen]
    field = (float(radius.min()), float(radius.max()))
    held, halves = omni["held"], omni["halves"]
    train = [i for i in range(len(observed)) if i not in held]
    cores = {tuple(indices): mrcal_fit.stereographic_core(observed[indices], size, spacing_m)
             for indices in [train] + halves}

    rows = []
    for k in knots:
        lensmodel = mrcal_fit.splined_model(k, fov_deg)
        log(f"{dataset.name}: mrcal {lensmodel}")
        start = time.perf_counter()
        problem, stats = mrcal_fit.splined_fit(core, lensmodel)
        row = dict(tool="mrcal", model=lensmodel, knots=k, views=len(observed),
                   seconds=time.perf_counter() - start + core_seconds,
                   core_focal_px=float(core["problem"]["intrinsics"][0][0]),
                   core_rms_px=mrcal_fit.fit_summary(core["problem"], core["stats"], observed)["rms_all_px"],
                   **mrcal_fit.fit_summary(problem, stats, observed))
        grid_residuals = mrcal_fit.corner_residuals(problem, observed)
        view_index = np.broadcast_to(np.arange(len(observed))[:, None, None], seen.shape)
        rows_cols = np.indices(seen.shape[1:]).transpose(1, 2, 0)[..., ::-1] * board.spacing_mm
        correlation, pairs = residual_structure.neighbour_correlation(
            grid_residuals[seen], view_index[seen], np.broadcast_to(rows_cols, seen.shape + (2,))[seen])
        row["structure"] = dict(neighbour_correlation=correlation, neighbour_pairs=pairs)
        row["params"] = row["intrinsics"]
        trained, _ = mrcal_fit.splined_fit(cores[tuple(train)], lensmodel)
        rms, _, per_view = mrcal_fit.held_out_rms(trained, observed[held])
        row["holdout"] = dict(rms_px=rms, per_view_px=per_view)
        fits = [mrcal_fit.splined_fit(cores[tuple(half)], lensmodel) for half in halves]
        boards_mm = (omni["row"].get("halves") or {}).get("boards_mm")
        row["halves"] = mrcal_fit.halves_diff(fits[0][0], fits[1][0], DISTANCE_MM / 1000.0, centre, field,
                                              *[observed[half][seen[half]][:, :2] for half in halves],
                                              align_at_m=boards_mm / 1000.0 if boards_mm else None)
        row["halves"]["half_rms_px"] = [mrcal_fit.fit_summary(p, s, observed[half])["rms_inliers_px"]
                                        for (p, s), half in zip(fits, halves)]
        rows.append(row)
    return dict(rows=rows, fov_deg=fov_deg, theta_deg=theta, field=field, centre=[float(c) for c in centre],
                free_core=[float(v) for v in free_core], corners=int(np.count_nonzero(seen)))


def compare(dataset, cli, knots, work, log):
    out = os.path.join(work, dataset.name)
    os.makedirs(out, exist_ok=True)
    omni = omnical_side(dataset, cli, out, log)
    mr = mrcal_side(dataset, omni, knots, log)
    board = omni["board"]
    return dict(dataset=dataset, rows=[omni["row"]] + mr["rows"],
                held=[os.path.basename(omni["names"][i]) for i in omni["held"]],
                halves=[len(h) for h in omni["halves"]], spacing_mm=board.spacing_mm,
                grid=(board.width, board.height), image_size=omni["image_size"],
                **{k: v for k, v in mr.items() if k != "rows"})


# ---------------------------------------------------------------------------- the document

def fmt(value, digits=3):
    return "n/a" if value is None else f"{value:.{digits}f}"


def pair(stats, a="diff_rms_px", b="diff_max_px"):
    if stats[a] is None:
        return "n/a (no overlap)"
    return f"{stats[a]:.3f} / {stats[b]:.3f}" + (f" ({stats['near_grid_points']} points)" if a.startswith("near") else "")


def tool_name(row):
    if row["tool"] == "omnical":
        return f"omnical ({row['model']})"
    return f"mrcal splined stereographic, {row['knots']} knots across"


def cells(row):
    missing = "n/a (flag missing)"
    held = fmt(row["holdout"]["rms_px"]) if row.get("holdout") else missing
    diff = pair(row["halves"]) if row.get("halves") else missing
    return [tool_name(row), str(row["params"]), f"{row['corners']} ({row['views']})", fmt(row["rms_all_px"]),
            fmt(row["rms_inliers_px"]), str(row["outliers"]), held, diff, f"{row['seconds']:.1f}"]


def joined(values, digits=3):
    return ", ".join(fmt(v, digits) for v in values)


def reading(results):
    """Sentences computed from the numbers, so that they stay true when regenerated."""
    lines, held_wins, halves_wins, fit_wins, compared = [], [], [], [], []
    for result in results:
        omni, mrcal_rows = result["rows"][0], result["rows"][1:]
        name = result["dataset"].name
        knots = ", ".join(str(r["knots"]) for r in mrcal_rows)
        text = (f"- **{name}** (mrcal with {knots} knots): in-sample (inliers) mrcal "
                f"{joined(r['rms_inliers_px'] for r in mrcal_rows)} px, omnical {fmt(omni['rms_inliers_px'])} px; "
                f"over all corners {joined(r['rms_all_px'] for r in mrcal_rows)} against "
                f"{fmt(omni['rms_all_px'])} px (omnical cuts {omni['outliers']} corners, mrcal "
                f"{', '.join(str(r['outliers']) for r in mrcal_rows)}).")
        if min(r["rms_inliers_px"] for r in mrcal_rows) < omni["rms_inliers_px"]:
            fit_wins.append(name)
        held = [r["holdout"]["rms_px"] for r in mrcal_rows]
        if omni.get("holdout"):
            compared.append(name)
            text += (f" Held out ({', '.join(result['held'])}): omnical {fmt(omni['holdout']['rms_px'])} px, "
                     f"mrcal {joined(held)} px.")
            if omni["holdout"]["rms_px"] < min(held):
                held_wins.append(name)
        else:
            text += f" Held out ({', '.join(result['held'])}): mrcal {joined(held)} px."
        diffs = [r["halves"]["diff_rms_px"] for r in mrcal_rows]
        near = [r["halves"]["near_diff_rms_px"] for r in mrcal_rows]
        text += (f" Halves at {DISTANCE_MM / 1000:g} m: mrcal {joined(diffs, 2)} px RMS "
                 f"({joined(near, 2)} where both halves have corners)")
        if omni.get("halves"):
            text += f", omnical {fmt(omni['halves']['diff_rms_px'])} px."
            if omni["halves"]["diff_rms_px"] < min(diffs):
                halves_wins.append(name)
        else:
            text += "."
        lines.append(text)
    if compared:
        sets = "dataset" if len(compared) == 1 else "datasets"
        lines += ["", f"Over the {len(compared)} {sets} with omnical's held-out figure: omnical predicts the "
                  f"held-out views better than every mrcal model on {len(held_wins)} "
                  f"({', '.join(held_wins) or 'none'}), and its two halves agree better on {len(halves_wins)} "
                  f"({', '.join(halves_wins) or 'none'}); mrcal fits the corners it was given more closely "
                  f"(inliers) on {len(fit_wins)} ({', '.join(fit_wins) or 'none'})."]
    return lines


def interpretation(results):
    """Our reading of why (an interpretation, not a measurement); the sphere part only
    when the sphere renders were run, the distances from the runs."""
    near = min(r["rows"][0]["board_mm"][0] for r in results) / 1000.0
    far = max(r["rows"][0]["board_mm"][1] for r in results) / 1000.0
    views = sorted({r["rows"][0]["views"] for r in results})
    text = ("Why, as we read it (an interpretation, not a measurement): mrcal's splined model is central and "
            "data-driven: a few hundred parameters describe the projection where the corners are, and its "
            "regularization pulls everything else towards the stereographic core. omnical's 7-10 parameters "
            "describe the mirror and the lens, so a view that lands where no other view was is predicted by the "
            f"optics, and the spread of viewpoints along the axis (boards at {near:.2f}-{far:.2f} m) is modelled "
            "rather than absorbed. Where mrcal fits the training corners more closely but predicts the held-out "
            "views worse, its extra parameters fit those views' noise and the detector's bias rather than the "
            "camera.")
    if any(r["dataset"].name.startswith("ohte-sph") for r in results):
        text += (" On the sphere renders the stereographic law is far from the mirror's (the stereographic focal "
                 "length that matches the sphere halves from the image centre to the rim), so the core is a poor "
                 "base and the spline, regularized towards it, cannot bend enough near the rim.")
    count = f"{views[0]}" if len(views) == 1 else f"{views[0]}-{views[-1]}"
    text += (f" These sets are small ({count} views; mrcal-calibrate-cameras' own documentation "
             "aims at about 100): the comparison says how each tool does with few views.")
    return text


def structure_section(results):
    """What is left in omnical's residuals for a more flexible model (residual_structure.py)."""
    out = ["", "## What is left in the residuals", "",
           "Could a more flexible term (a figure error, lens decentering, a residual distortion) fit the corners "
           "better *and* predict new views better? Measured on the full-set fits' residuals over all corners "
           "(`tests/bench/mrcal_compare/residual_structure.py` defines each column):", "",
           "| dataset | omnical RMS all (px) | neighbour correlation: omnical; mrcal per knot count | "
           "image-plane correction field, each view left out in turn: RMS with none; best held out (knots, ridge) "
           "| the same fields in-sample: lowest RMS (parameters) |", "| --- | --- | --- | --- | --- |"]
    lines = []
    for result in results:
        omni, mrcal_rows = result["rows"][0], result["rows"][1:]
        structure = omni.get("structure")
        if not structure:
            continue
        field = structure["field"]
        best, richest = field["best"], field["richest"]
        mrcal_correlations = [f"{r['structure']['neighbour_correlation']:+.3f}" for r in mrcal_rows]
        out.append(f"| {result['dataset'].name} | {fmt(omni['rms_all_px'])} | "
                   f"{structure['neighbour_correlation']:+.3f}; {'; '.join(mrcal_correlations)} "
                   f"({structure['neighbour_pairs']} pairs) | {fmt(field['none_rms_px'], 4)}; "
                   f"{fmt(best['held_out_rms_px'], 4)} ({best['knots']} x {best['knots']}, {best['ridge']:g}) | "
                   f"{fmt(richest['train_rms_px'])} ({richest['params']}) |")
        gain = 1.0 - best["held_out_rms_px"] / field["none_rms_px"]
        verdict = ("no field predicts a left-out view's residuals better than none by 1 % or more"
                   if gain < 0.01 else f"the best field predicts left-out views {100 * gain:.1f} % better than none")
        lines.append(f"- **{result['dataset'].name}**: {verdict} (in-sample the richest field reaches "
                     f"{fmt(richest['train_rms_px'])} px with {richest['params']} parameters); omnical's neighbouring "
                     f"corners' residuals correlate {structure['neighbour_correlation']:+.3f}, mrcal's "
                     f"{', '.join(mrcal_correlations)}.")
    if not lines:
        return []
    absorbed = [r["dataset"].name for r in results if r["rows"][0].get("structure")
                and r["rows"][0]["structure"]["neighbour_correlation"] > 0.1
                and all(m["structure"]["neighbour_correlation"] < 0.05 for m in r["rows"][1:])]
    reading_text = ("Reading: where no field learnt on the other views helps a left-out view, what remains belongs "
                    "to each view alone: neighbouring corners of one view may err alike (the board's own shape in "
                    "that view: a hand-held paper sheet bends differently each time) without the error recurring "
                    "where other views see the same pixels. Parameters that only one or two views constrain can "
                    "absorb it in-sample and predict the held-out views worse for it")
    if absorbed:
        reading_text += (f": on {', '.join(absorbed)} omnical's neighbouring residuals correlate and mrcal's no "
                         "longer do")
    return out + [""] + lines + ["", reading_text + "."]


def write_document(path, results, cli, quick, checkerboard_subpixel, seconds):
    header = ["dataset", "tool / model", "intrinsic params", "corners (views)", "RMS all (px)", "RMS inliers (px)",
              "outliers", "held-out RMS (px)", f"halves diff at {DISTANCE_MM / 1000:g} m, RMS / max (px)", "time (s)"]
    out = ["# omnical vs mrcal 2.2, same corners", "",
           "Generated by `tests/bench/mrcal_compare/mrcal_compare.py`; do not edit. Regenerate with", "",
           "```sh", COMMAND + (" --quick" if quick else "") + (" --checkerboard-subpixel" if checkerboard_subpixel else ""), "```", "",
           "(Debian's `/usr/bin/python3` with `python3-mrcal`; with `PYTHONPATH=build/test/python` omnical's "
           "Python module projects the all-corner residuals, else `omnical project` does; ~8 min on 2 cores, "
           "most of it mrcal on the aprilgrid's 76 x 76 board grid.)"
           + (" **Quick run: the real set and the 10-knot model only.**" if quick else ""), "",
           "Both tools calibrate from the same corners: omnical's detections (`calibrate --images`, "
           "`detections.json`). mrcal fits its richest central model, LENSMODEL_SPLINED_STEREOGRAPHIC; omnical "
           "its non-central mirror model (`calibrate --detections --board-warp`, with `--holdout` and "
           "`--cross-validate` for the last two columns). Both fit the board's warp (mrcal's calobject_warp, "
           "omnical's `--board-warp`: the same paraboloid model); without a guess omnical also fits the board's "
           "relief where held-out folds choose it (`--board-relief`: each corner's own offset, one board "
           "parameter per corner, not counted among the intrinsic parameters, as neither tool counts its warp). "
           "Definitions below the tables.", "",
           "| " + " | ".join(header) + " |", "|" + " --- |" * len(header)]
    for result in results:
        label = f"{result['dataset'].name}: {result['dataset'].label}"
        out += ["| " + " | ".join([label] + cells(row)) + " |" for row in result["rows"]]
    out += ["", "Per dataset: the held-out views (per view: omnical; mrcal per knot count), the halves' own fit "
            "(RMS over each half's inliers), the observed field.", ""]
    for result in results:
        omni, mrcal_rows = result["rows"][0], result["rows"][1:]
        views = []
        for v, name in enumerate(result["held"]):
            o = omni["holdout"]["per_view_px"][v] if omni.get("holdout") else None
            views.append(f"{name} ({fmt(o)}; {joined(r['holdout']['per_view_px'][v] for r in mrcal_rows)})")
        halves_fit = [f"mrcal {r['knots']}: {joined(r['halves']['half_rms_px'])}" for r in mrcal_rows]
        if omni.get("halves") and omni["halves"].get("half_rms_px"):
            halves_fit.insert(0, f"omnical: {joined(omni['halves']['half_rms_px'])}")
        boards = ""
        if omni.get("halves") and omni["halves"].get("boards_mm"):
            per_tool = [f"omnical {pair(omni['halves'], 'boards_diff_rms_px', 'boards_diff_max_px')}"]
            per_tool += [f"mrcal {r['knots']}: {pair(r['halves'], 'boards_diff_rms_px', 'boards_diff_max_px')}"
                         for r in mrcal_rows]
            boards = (f"halves at {DISTANCE_MM / 1000:g} m with one alignment fitted at the boards' "
                      f"{omni['halves']['boards_mm']:.0f} mm, RMS / max: {'; '.join(per_tool)} px; ")
        out.append(f"- {result['dataset'].name}: {result['corners']} corners; held out {', '.join(views)}; "
                   f"halves of {result['halves'][0]} and {result['halves'][1]} views, fit to {'; '.join(halves_fit)} px; "
                   f"{boards}observed field r = {result['field'][0]:.0f}-{result['field'][1]:.0f} px around "
                   f"({result['centre'][0]:.1f}, {result['centre'][1]:.1f}), corners up to "
                   f"{result['theta_deg']:.1f} deg off the stereographic axis.")
    out += ["", "mrcal details (full-set fits):", "",
            "| dataset | lens model string | board grid (spacing) | stereographic core: focal (px), RMS (px) "
            "| free core as mrcal-calibrate-cameras: fx, fy, cx, cy (px) | mrcal's own `rms_reproj_error__pixels` "
            "| measurements | calobject_warp (mm) | halves diff where both halves have corners, RMS / max (px) |",
            "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for result in results:
        free = ", ".join(f"{v:.0f}" for v in result["free_core"])
        for row in result["rows"][1:]:
            warp = "n/a" if row["warp_mm"] is None else f"{row['warp_mm'][0]:.3f}, {row['warp_mm'][1]:.3f}"
            out.append(f"| {result['dataset'].name} | `{row['model']}` | {result['grid'][0]} x {result['grid'][1]} "
                       f"({result['spacing_mm']:g} mm) | {row['core_focal_px']:.1f}, {row['core_rms_px']:.2f} | "
                       f"{free} | {row['mrcal_rms_px']:.3f} | {row['mrcal_measurements']} | {warp} | "
                       f"{pair(row['halves'], 'near_diff_rms_px', 'near_diff_max_px')} |")
    out += structure_section(results)
    out += ["", "## Definitions", ""] + DEFINITIONS + ["", "## Reading", ""] + reading(results) + ["", interpretation(results)]
    out += ["", f"Generated in {seconds:.0f} s; omnical flags found: --holdout {'yes' if cli.has_holdout else 'no'}, "
            f"--cross-validate {'yes' if cli.has_cross_validate else 'no'}, diff {'yes' if cli.has_diff else 'no'}.", ""]
    with open(path, "w") as handle:
        handle.write("\n".join(out))


# ---------------------------------------------------------------------------- main

def check_finite(results):
    for result in results:
        for row in result["rows"]:
            values = [row["rms_all_px"], row["rms_inliers_px"]]
            for key in ("holdout", "halves"):
                for name, value in (row.get(key) or {}).items():
                    if name.endswith("_px"):
                        values += value if isinstance(value, list) else [value]
            if not all(isinstance(v, (int, float)) and math.isfinite(v) and v >= 0 for v in values):
                raise BenchError(f"{result['dataset'].name}: {row['tool']} {row['model']}: a non-finite figure {values}")
            structure = row.get("structure") or {}
            figures = [structure.get("neighbour_correlation", 0.0)]
            if "field" in structure:
                figures += [structure["field"]["none_rms_px"], structure["field"]["best"]["held_out_rms_px"]]
            if not all(math.isfinite(v) for v in figures):
                raise BenchError(f"{result['dataset'].name}: {row['tool']} {row['model']}: a non-finite residual "
                                 f"structure figure {figures}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--omnical", required=True, help="the omnical binary")
    parser.add_argument("--out", required=True, help="the Markdown file to write")
    parser.add_argument("--quick", action="store_true", help="the real set and the 10-knot model only")
    parser.add_argument("--work", help="keep the intermediate outputs here (default: a temporary directory)")
    parser.add_argument("--real-data", default=os.path.join(ROOT, "..", "shared", "real-data", "mei-parabolic"),
                        help="the mei-parabolic images (default: ../shared/real-data/mei-parabolic)")
    parser.add_argument("--datasets", help="comma-separated subset of the dataset names")
    parser.add_argument("--extra", action="append", default=[], metavar="NAME=TARGET.yaml:IMAGE_DIR",
                        help="one more image set (repeatable), calibrated without a guess")
    parser.add_argument("--checkerboard-subpixel", action="store_true",
                        help="checkerboard corners from `calibrate --images --checkerboard-subpixel` (both tools fit them)")
    args = parser.parse_args()

    if not os.path.isdir(args.real_data):
        print(f"SKIP: {os.path.abspath(args.real_data)}: real-data folder absent")
        return SKIP

    start = time.perf_counter()
    cli = Omnical(args.omnical)
    chosen = datasets(os.path.abspath(args.real_data))
    if args.quick:
        chosen = chosen[:1]
    chosen += [extra_dataset(spec) for spec in args.extra]
    if args.datasets:
        wanted = args.datasets.split(",")
        unknown = set(wanted) - {d.name for d in chosen}
        if unknown:
            raise BenchError(f"--datasets: unknown {', '.join(sorted(unknown))}")
        chosen = [d for d in chosen if d.name in wanted]
    if args.checkerboard_subpixel:
        for d in chosen:
            with open(d.target) as spec:
                if re.search(r"^target_type:\s*'?checkerboard", spec.read(), re.MULTILINE):
                    d.detect_options = ["--checkerboard-subpixel"]
    knots = KNOTS[:1] if args.quick else KNOTS
    work = os.path.abspath(args.work) if args.work else tempfile.mkdtemp(prefix="mrcal_compare.")
    log = (lambda message: print(message, file=sys.stderr, flush=True))
    try:
        results = [compare(d, cli, knots, work, log) for d in chosen]
    finally:
        if not args.work:
            shutil.rmtree(work, ignore_errors=True)
    check_finite(results)
    out_dir = os.path.dirname(os.path.abspath(args.out))
    if not os.path.isdir(out_dir):
        raise BenchError(f"{args.out}: no directory {out_dir}")
    write_document(args.out, results, cli, args.quick, args.checkerboard_subpixel, time.perf_counter() - start)
    if not os.path.getsize(args.out):
        raise BenchError(f"{args.out}: written empty")
    print(f"wrote {args.out}")
    return 0


def missing_dependency():
    try:
        import numpy  # noqa: F401
        import numpysane  # noqa: F401
        import cv2  # noqa: F401
        import mrcal  # noqa: F401
    except ImportError as error:
        return str(error)
    return None


if __name__ == "__main__":
    missing = missing_dependency()
    if missing:
        print(f"SKIP: mrcal_compare needs python3-mrcal (with numpy, cv2) in {sys.executable}: {missing}")
        sys.exit(SKIP)
    from omnical_runs import BenchError, Omnical
    try:
        sys.exit(main())
    except BenchError as error:
        print(f"mrcal_compare: {error}", file=sys.stderr)
        sys.exit(1)
