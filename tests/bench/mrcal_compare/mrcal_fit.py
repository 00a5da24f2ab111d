"""The mrcal side of the comparison (mrcal 2.2, Debian's python3-mrcal).

mrcal calibrates from the corners omnical detected, laid out on mrcal's regular board
grid (omnical_runs.Board). The solve follows mrcal-calibrate-cameras (v2.2,
solve_initial() and the final solve), with our own per-view pose seed:

1. LENSMODEL_STEREOGRAPHIC seed: focal estimates from the corners' image radius, the
   projection centre at the imager centre; each board pose by PnP through a virtual
   pinhole turned towards that board (mrcal.seed_stereographic() runs solvePnP on a
   pinhole reprojection of the whole field, which cannot hold rays past 90 deg off the
   axis: this camera sees past 90 deg).
2. geometry only (no outlier rejection, no regularization). mrcal-calibrate-cameras then
   frees the whole core; here the centre stays at the imager centre and fx = fy, the
   focal searched: a free stereographic core runs away on the sphere-mirror renders
   (its centre 280 px off, fx / fy 0.84), and the splined model, whose core is held,
   cannot bring it back (free_stereographic_core() keeps that variant for the record).
3. the splined model: the stereographic core held (as mrcal-calibrate-cameras holds
   a splined model's core), spline values seeded at +-1e-6, outlier rejection and
   regularization on, board warp off; then the final solve with calobject_warp
   optimised from (0, 0).

Residuals are recomputed here per corner from the fitted geometry (mrcal's solver
vector holds 0 for outliers and adds regularization terms).
"""
import numpy as np
import numpysane as nps

import mrcal

STEREOGRAPHIC = "LENSMODEL_STEREOGRAPHIC"


class FitError(Exception):
    pass


def splined_model(knots, fov_x_deg):
    """A square knot grid: the mirror's image is a disc, so the spline's domain is too."""
    return f"LENSMODEL_SPLINED_STEREOGRAPHIC_order=3_Nx={knots}_Ny={knots}_fov_x_deg={fov_x_deg}"


def _turn_to_z(direction):
    """Rotation taking the unit vector `direction` to +z."""
    axis = np.cross(direction, (0.0, 0.0, 1.0))
    sine, cosine = np.linalg.norm(axis), direction[2]
    if sine < 1e-12:
        return np.eye(3) if cosine > 0 else np.diag((1.0, -1.0, -1.0))
    return mrcal.R_from_r(axis / sine * np.arctan2(sine, cosine))


def seed_frames(observations, lensmodel, intrinsics, spacing_m):
    """Board poses (rt, board -> camera) by PnP through a virtual pinhole per view."""
    import cv2

    height, width = observations.shape[1:3]
    board = mrcal.ref_calibration_object(width, height, spacing_m)
    frames = []
    for view in observations:
        seen = view[..., 2] > 0
        rays = mrcal.unproject(np.ascontiguousarray(view[seen][:, :2]), lensmodel, intrinsics, normalize=True)
        mean = np.nanmean(rays, axis=0)
        turn = _turn_to_z(mean / np.linalg.norm(mean))
        turned = rays @ turn.T
        keep = np.isfinite(turned).all(axis=1) & (turned[:, 2] > 1e-3)
        if np.count_nonzero(keep) < 4:
            raise FitError("a board spans more than a hemisphere of rays: no pinhole seed")
        pinhole = turned[keep, :2] / turned[keep, 2:]
        ok, rvec, tvec = cv2.solvePnP(board[seen][keep].reshape(-1, 1, 3), pinhole.reshape(-1, 1, 2),
                                      np.eye(3), None)
        if not ok:
            raise FitError("solvePnP failed on a view")
        virtual_from_board = mrcal.Rt_from_rt(np.concatenate((rvec.ravel(), tvec.ravel())))
        camera_from_virtual = nps.glue(turn.T, np.zeros(3), axis=-2)
        frames.append(mrcal.rt_from_Rt(mrcal.compose_Rt(camera_from_virtual, virtual_from_board)))
    return np.array(frames)


def _problem(observations, lensmodel, intrinsics, frames, imager_size, spacing_m):
    count = len(observations)
    return dict(intrinsics=np.atleast_2d(np.array(intrinsics, dtype=float)),
                extrinsics_rt_fromref=np.zeros((0, 6)),
                frames_rt_toref=np.array(frames, dtype=float),
                points=None,
                observations_board=np.array(observations, dtype=float),
                indices_frame_camintrinsics_camextrinsics=np.array([[i, 0, -1] for i in range(count)], dtype=np.int32),
                observations_point=None,
                indices_point_camintrinsics_camextrinsics=None,
                lensmodel=lensmodel,
                imagersizes=np.array([imager_size], dtype=np.int32),
                calibration_object_spacing=spacing_m,
                calobject_warp=None,
                do_optimize_intrinsics_core=False,
                do_optimize_intrinsics_distortions=False,
                do_optimize_extrinsics=False,
                do_optimize_frames=True,
                do_optimize_calobject_warp=False,
                do_apply_outlier_rejection=False,
                do_apply_regularization=False,
                verbose=False)


def _optimize(problem):
    stats = mrcal.optimize(**problem)
    if not stats or not np.isfinite(stats.get("rms_reproj_error__pixels", np.nan)) or \
            stats["rms_reproj_error__pixels"] < 0:
        raise FitError(f"mrcal.optimize failed ({problem['lensmodel']})")
    return stats


def _geometry_fit(observations, focal, centre, imager_size, spacing_m):
    intrinsics = (focal, focal) + tuple(centre)
    frames = seed_frames(observations, STEREOGRAPHIC, intrinsics, spacing_m)
    problem = _problem(observations, STEREOGRAPHIC, intrinsics, frames, imager_size, spacing_m)
    return problem, _optimize(problem)


def _focal_candidates(observations, centre):
    # The outermost corner at 90-150 deg off the axis: r = 2 f tan(theta / 2).
    seen = observations[..., 2] > 0
    radius = np.hypot(observations[..., 0] - centre[0], observations[..., 1] - centre[1])[seen].max()
    return [radius / (2.0 * np.tan(np.radians(theta_deg) / 2.0)) for theta_deg in (90, 105, 120, 135, 150)]


def stereographic_core(observations, imager_size, spacing_m, iterations=8):
    """Steps 1-2 with the projection centre held at the imager centre (where mrcal's seed
    puts it) and fx = fy: geometry-only fits over focal estimates, then a golden-section
    search on log f around the best. A free core (mrcal-calibrate-cameras) runs away on a
    sphere mirror, whose law is far from stereographic (free_stereographic_core)."""
    width, height = imager_size
    centre = ((width - 1) / 2.0, (height - 1) / 2.0)
    tried = {}

    def rms(log_focal):
        if log_focal not in tried:
            try:
                tried[log_focal] = _geometry_fit(observations, float(np.exp(log_focal)), centre, imager_size, spacing_m)
            except FitError:
                tried[log_focal] = None
        fit = tried[log_focal]
        return np.inf if fit is None else fit[1]["rms_reproj_error__pixels"]

    starts = [np.log(f) for f in _focal_candidates(observations, centre)]
    best = min(starts, key=rms)
    if not np.isfinite(rms(best)):
        raise FitError("no focal estimate gave a stereographic seed")
    golden = (np.sqrt(5.0) - 1.0) / 2.0
    low, high = best - np.log(1.25), best + np.log(1.25)
    a, b = high - golden * (high - low), low + golden * (high - low)
    for _ in range(iterations):
        if rms(a) < rms(b):
            high, b = b, a
            a = high - golden * (high - low)
        else:
            low, a = a, b
            b = low + golden * (high - low)
    chosen = min(tried, key=rms)
    problem, stats = tried[chosen]
    return dict(problem=problem, stats=stats, focal_seed_px=float(np.exp(best)))


def free_stereographic_core(observations, imager_size, spacing_m):
    """mrcal-calibrate-cameras' steps 1-2 as they are (the whole core free), for the record."""
    width, height = imager_size
    centre = ((width - 1) / 2.0, (height - 1) / 2.0)
    best = None
    for focal in _focal_candidates(observations, centre):
        try:
            problem, _ = _geometry_fit(observations, focal, centre, imager_size, spacing_m)
            problem["do_optimize_intrinsics_core"] = True
            stats = _optimize(problem)
        except FitError:
            continue
        if best is None or stats["rms_reproj_error__pixels"] < best[1]["rms_reproj_error__pixels"]:
            best = (problem, stats)
    if best is None:
        raise FitError("no focal estimate gave a stereographic seed")
    return dict(problem=best[0], stats=best[1])


def field_theta_deg(core_problem, observations):
    """The largest angle off the stereographic axis among the corners."""
    seen = observations[..., 2] > 0
    rays = mrcal.unproject(np.ascontiguousarray(observations[seen][:, :2]), STEREOGRAPHIC,
                           core_problem["intrinsics"][0], normalize=True)
    return float(np.degrees(np.nanmax(np.arccos(np.clip(rays[:, 2], -1.0, 1.0)))))


def splined_fit(core, lensmodel, seed=0):
    """Step 3 from a stereographic core: returns the solved problem and mrcal's stats."""
    problem = {key: (value.copy() if isinstance(value, np.ndarray) else value)
               for key, value in core["problem"].items()}
    extra = mrcal.lensmodel_num_params(lensmodel) - 4
    rng = np.random.default_rng(seed)
    problem["intrinsics"] = nps.glue(problem["intrinsics"][:, :4], (rng.random((1, extra)) - 0.5) * 2e-6, axis=-1)
    problem.update(lensmodel=lensmodel, do_optimize_intrinsics_core=False, do_optimize_intrinsics_distortions=True,
                   do_apply_outlier_rejection=True, do_apply_regularization=True)
    _optimize(problem)
    problem["calobject_warp"] = np.zeros(2)
    problem["do_optimize_calobject_warp"] = True
    stats = _optimize(problem)
    return problem, stats


def corner_residuals(problem, observed):
    """Per-corner projection - observation (px) from the fitted geometry, shape (views, H, W, 2)."""
    camera_points = mrcal.hypothesis_board_corner_positions(**problem)[0]
    projected = mrcal.project(camera_points, problem["lensmodel"], problem["intrinsics"][0])
    return projected - observed[..., :2]


def corner_errors(problem, observed):
    """Per-corner |projection - observation| (px) from the fitted geometry, shape (views, H, W)."""
    return np.linalg.norm(corner_residuals(problem, observed), axis=-1)


def fit_summary(problem, stats, observed):
    """RMS per corner over all corners and over mrcal's inliers, and the outlier count."""
    seen = observed[..., 2] > 0
    inlier = seen & (problem["observations_board"][..., 2] > 0)
    errors = corner_errors(problem, observed)
    measurements = mrcal.num_measurements(**problem)
    return dict(rms_all_px=float(np.sqrt(np.mean(errors[seen] ** 2))),
                rms_inliers_px=float(np.sqrt(np.mean(errors[inlier] ** 2))),
                corners=int(np.count_nonzero(seen)),
                outliers=int(np.count_nonzero(seen & ~inlier)),
                mrcal_rms_px=float(stats["rms_reproj_error__pixels"]),
                mrcal_measurements=int(measurements),
                warp_mm=[1000.0 * w for w in problem["calobject_warp"]] if problem.get("calobject_warp") is not None else None,
                intrinsics=len(problem["intrinsics"][0]))


def held_out_rms(trained, held_observations):
    """Held-out views (BabelCalib's protocol): the intrinsics and board warp fixed, each
    held-out board's pose fitted, per-corner RMS over all held-out corners (no rejection)."""
    lensmodel, intrinsics = trained["lensmodel"], trained["intrinsics"][0]
    spacing = trained["calibration_object_spacing"]
    size = tuple(trained["imagersizes"][0])
    frames = seed_frames(held_observations, lensmodel, intrinsics, spacing)
    problem = _problem(held_observations, lensmodel, intrinsics, frames, size, spacing)
    problem["calobject_warp"] = None if trained.get("calobject_warp") is None else trained["calobject_warp"].copy()
    _optimize(problem)
    errors = corner_errors(problem, held_observations)
    seen = held_observations[..., 2] > 0
    per_view = [float(np.sqrt(np.mean(e[s] ** 2))) for e, s in zip(errors, seen)]
    return float(np.sqrt(np.mean(errors[seen] ** 2))), int(np.count_nonzero(seen)), per_view


def field_mask(grid_px, centre_px, radius_range_px):
    """The observed field: the annulus of radii the corners cover around the centre, all round."""
    radius = np.hypot(grid_px[..., 0] - centre_px[0], grid_px[..., 1] - centre_px[1])
    return (radius >= radius_range_px[0]) & (radius <= radius_range_px[1])


def _gap_px(grid, corners_px):
    """Distance from each grid point to the nearest corner."""
    return np.min(np.hypot(grid[..., None, 0] - corners_px[None, None, :, 0],
                           grid[..., None, 1] - corners_px[None, None, :, 1]), axis=-1)


def halves_diff(problem_a, problem_b, distance_m, centre_px, radius_range_px, corners_a_px, corners_b_px,
                step_px=16.0, near_px=24.0, min_points=10, align_at_m=None):
    """mrcal.projection_diff of two fits at `distance_m` over the observed field, the
    implied transform between the two camera frames fitted over that field
    (projection_diff's default focus, a disc at the imager centre, is the camera's own
    reflection here: no data). The near_* figures: the grid points within `near_px` of a
    corner of each half (both calibrations have data there), aligned over those points;
    None when fewer than `min_points`. The boards_* figures (with `align_at_m`): the
    transform fitted over the field at that distance (the boards') and applied at
    `distance_m`, as omnical's cross_validation.aligned_at_boards."""
    models = [mrcal.cameramodel(optimization_inputs=p, icam_intrinsics=0) for p in (problem_a, problem_b)]
    width, height = models[0].imagersize()
    columns = int(round((width - 1) / step_px)) + 1
    rows = int(round((height - 1) / step_px)) + 1
    rays, grid = mrcal.sample_imager_unproject(columns, rows, width, height,
                                               [m.intrinsics()[0] for m in models],
                                               [m.intrinsics()[1] for m in models], normalize=True)
    inside = field_mask(grid, centre_px, radius_range_px)
    both = inside & (_gap_px(grid, corners_a_px) <= near_px) & (_gap_px(grid, corners_b_px) <= near_px)
    out = {}
    passes = [("", inside, distance_m), ("near_", both, distance_m)]
    if align_at_m:
        passes.append(("boards_", inside, align_at_m))
    for key, mask, fit_at_m in passes:
        if np.count_nonzero(mask) < min_points:
            out.update({f"{key}diff_rms_px": None, f"{key}diff_max_px": None, f"{key}grid_points": 0})
            continue
        implied = mrcal.implied_Rt10__from_unprojections(grid, rays[0] * fit_at_m, rays[1],
                                                         weights=mask.astype(float), atinfinity=False)
        difflen = mrcal.projection_diff(models, implied_Rt10=implied, gridn_width=columns, gridn_height=rows,
                                        distance=distance_m, use_uncertainties=False)[0]
        values = difflen[mask]
        finite = values[np.isfinite(values)]
        if finite.size == 0:
            raise FitError("projection_diff: no finite value over the observed field")
        out.update({f"{key}diff_rms_px": float(np.sqrt(np.mean(finite ** 2))),
                    f"{key}diff_max_px": float(finite.max()), f"{key}grid_points": int(finite.size),
                    f"{key}unprojectable": int(values.size - finite.size)})
    if out["diff_rms_px"] is None:
        raise FitError("the observed field holds too few grid points")
    return out
