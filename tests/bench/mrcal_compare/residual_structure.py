"""Is anything left in a fit's residuals that a more flexible model could learn?

Two measurements on per-corner residual vectors (projection - observation, px):

- neighbour correlation: over pairs of corners of one view that are nearest neighbours
  on the board, mean(e_a . e_b) / mean(|e|^2) (every corner, outliers too). A model error
  or a smooth board bend moves neighbours alike (towards +1); independent corner errors
  give ~0; a model that fits each view's noise pushes neighbours apart (below 0).
- an image-plane correction field, learnt from the residuals of all views but one and
  applied to the one left out (every view in turn): what a flexible non-symmetric term (a
  figure error, lens decentering, a residual distortion) could add to a prediction. The
  field is bilinear on an n x n knot grid over the corners' bounding box, its values
  fitted by ridge least squares; the held-out RMS is over every view's corners after
  their own field was subtracted. The residuals come from one fit of every view, so the
  left-out view's pose (and the intrinsics) saw it: a refit could absorb part of a field,
  and part of what the field learns may be that view's own error. A field that does not
  predict the left-out views says the residuals hold no structure recurring across views.

Numbers only (numpy); the caller writes them into the document.
"""
import numpy as np

KNOT_GRIDS = (3, 4, 6, 10)
RIDGES = (0.01, 1.0, 10.0, 100.0)


def rms(residuals):
    return float(np.sqrt(np.mean(np.sum(residuals ** 2, axis=1)))) if len(residuals) else float("nan")


def neighbour_correlation(residuals, view_of, board_xy_mm):
    """mean(e_a . e_b) / mean(|e|^2) over same-view pairs at the board's nearest-neighbour
    distance (within 1 %), and the number of pairs."""
    points = np.asarray(board_xy_mm, dtype=float)
    residuals = np.asarray(residuals, dtype=float)
    view_of = np.asarray(view_of)
    views = [np.flatnonzero(view_of == v) for v in np.unique(view_of)]
    gaps = [np.hypot(*(points[i][:, None, :] - points[i][None, :, :]).transpose(2, 0, 1)) for i in views]
    positive = [g[g > 1e-9] for g in gaps]
    if not any(p.size for p in positive):
        return float("nan"), 0
    nearest = min(p.min() for p in positive if p.size)
    dots = []
    for rows, gap in zip(views, gaps):
        a, b = np.nonzero(np.triu((gap > 1e-9) & (gap <= 1.01 * nearest), 1))
        dots.append(np.sum(residuals[rows[a]] * residuals[rows[b]], axis=1))
    dots = np.concatenate(dots)
    if dots.size == 0:
        return float("nan"), 0
    return float(np.mean(dots) / np.mean(np.sum(residuals ** 2, axis=1))), int(dots.size)


def _hat(values, low, high, knots):
    t = np.clip((values - low) / (high - low), 0.0, 1.0) * (knots - 1)
    index = np.clip(np.floor(t).astype(int), 0, knots - 2)
    fraction = t - index
    basis = np.zeros((len(values), knots))
    rows = np.arange(len(values))
    basis[rows, index] = 1.0 - fraction
    basis[rows, index + 1] = fraction
    return basis


def _field_basis(pixels, low, high, knots):
    bx = _hat(pixels[:, 0], low[0], high[0], knots)
    by = _hat(pixels[:, 1], low[1], high[1], knots)
    return (bx[:, :, None] * by[:, None, :]).reshape(len(pixels), -1)


def correction_field(pixels, residuals, view_of, knot_grids=KNOT_GRIDS, ridges=RIDGES):
    """Leave-one-view-out image-plane correction fields: per (knots, ridge) the in-sample
    RMS (learnt on every view) and the held-out RMS; the best held-out one; the RMS with no
    field."""
    pixels, residuals, view_of = (np.asarray(a) for a in (pixels, residuals, view_of))
    low, high = pixels.min(axis=0) - 1.0, pixels.max(axis=0) + 1.0
    views = np.unique(view_of)
    fields = []
    for knots in knot_grids:
        basis = _field_basis(pixels, low, high, knots)
        for ridge in ridges:
            def solve(rows):
                b = basis[rows]
                return np.linalg.solve(b.T @ b + ridge * np.eye(b.shape[1]), b.T @ residuals[rows])
            held = np.empty_like(residuals, dtype=float)
            for view in views:
                out = view_of == view
                held[out] = residuals[out] - basis[out] @ solve(~out)
            fields.append(dict(knots=knots, ridge=ridge, params=2 * knots * knots,
                               train_rms_px=rms(residuals - basis @ solve(np.ones(len(pixels), bool))),
                               held_out_rms_px=rms(held)))
    best = min(fields, key=lambda f: f["held_out_rms_px"])
    richest = min(fields, key=lambda f: f["train_rms_px"])
    return dict(none_rms_px=rms(residuals), best=best, richest=richest, fields=fields, views=int(len(views)))
