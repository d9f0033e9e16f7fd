"""Several lights beside their ground truth (paper Fig. 11 / Fig. 13 layout).

Offers
------
light_set_mosaic : one 8-bit image, a row per light: estimated and exact shadow times of
    each sweep, then the light's dual view.
"""

import numpy as np

from shadowcam.io.images import colormap_rgb8, preview_rgb8

#: pixels between tiles
_GAP = 2


def _fit(tile, height, width):
    """`tile` (rows, cols, 3) uint8 pasted at the top left of a white (height, width) tile."""
    out = np.full((height, width, 3), 255, np.uint8)
    out[:tile.shape[0], :tile.shape[1]] = tile[:height, :width]
    return out


def light_set_mosaic(times, truths, dual_views):
    """Tile per-light time maps, their ground truth and dual views.

    Parameters
    ----------
    times : (S, L, H, W) array_like
        Estimated shadow times per sweep and light (NaN = flagged).
    truths : (S, L, H, W) array_like
        Exact times, same layout.
    dual_views : (L, V, U, C) array_like
        Each light's dual view (NaN = hole).

    Returns
    -------
    (rows, cols, 3) uint8 ndarray
        ``L`` rows of ``2 S + 1`` tiles; each sweep's maps share one colour scale.
    """
    times, truths = np.asarray(times, np.float64), np.asarray(truths, np.float64)
    dual_views = np.asarray(dual_views, np.float64)
    if times.shape != truths.shape or times.ndim != 4 or dual_views.shape[0] != times.shape[1]:
        raise ValueError(f"times and truths must be (S, L, H, W) and dual_views (L, V, U, C) with the "
                         f"same L; got {times.shape}, {truths.shape}, {dual_views.shape}")
    n_sweeps, n_lights, height, width = times.shape
    tile_h, tile_w = max(height, dual_views.shape[1]), max(width, dual_views.shape[2])
    rows = []
    for k in range(n_lights):
        tiles = []
        for s in range(n_sweeps):
            finite = truths[s][np.isfinite(truths[s])]
            vmin, vmax = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
            for image in (times[s, k], truths[s, k]):
                tiles.append(_fit(colormap_rgb8(image, vmin=vmin, vmax=vmax), tile_h, tile_w))
        tiles.append(_fit(preview_rgb8(dual_views[k]), tile_h, tile_w))
        gap = np.full((tile_h, _GAP, 3), 255, np.uint8)
        rows.append(np.concatenate([part for tile in tiles for part in (tile, gap)][:-1], axis=1))
        rows.append(np.full((_GAP, rows[-1].shape[1], 3), 255, np.uint8))
    return np.concatenate(rows[:-1], axis=0)
