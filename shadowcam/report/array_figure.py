"""The virtual camera array beside its ground truth (paper Fig. 6 layout).

Offers
------
array_mosaic : one 8-bit image: each camera's view (left block) and the reciprocal render
    of the same crossing (right block), cameras in their array rows and columns.
"""

import numpy as np

from shadowcam.io.images import preview_rgb8

#: pixels between tiles
_GAP = 2


def array_mosaic(views, reciprocal, *, percentile=99.0):
    """Tile the array's views and their reciprocal renders.

    Parameters
    ----------
    views : (n, m, V, U, C) array_like
        Estimated views (NaN = hole, drawn in the hole colour).
    reciprocal : (n, m, V, U, C) array_like
        Ground-truth views of the same cameras.
    percentile : float
        Exposure of each block (:func:`shadowcam.io.images.tone_map`).

    Returns
    -------
    (rows, cols, 3) uint8 ndarray
        ``n`` rows of ``2 m`` tiles: the ``m`` estimated views, then the ``m`` reciprocal
        renders, separated by a wider gap.
    """
    views, reciprocal = np.asarray(views, np.float64), np.asarray(reciprocal, np.float64)
    if views.shape != reciprocal.shape or views.ndim != 5:
        raise ValueError(f"views and reciprocal must both be (n, m, V, U, C); got {views.shape} and "
                         f"{reciprocal.shape}")
    n, m, height, width = views.shape[:4]
    out = np.full((n * (height + _GAP) - _GAP, 2 * m * (width + _GAP) + 2 * _GAP, 3), 255, np.uint8)
    for block, images in enumerate((views, reciprocal)):
        tiles = preview_rgb8(np.concatenate([np.concatenate(list(row), axis=1) for row in images], axis=0),
                             percentile=percentile)
        for i in range(n):
            for j in range(m):
                tile = tiles[i * height:(i + 1) * height, j * width:(j + 1) * width]
                y = i * (height + _GAP)
                x = block * (m * (width + _GAP) + 2 * _GAP) + j * (width + _GAP)
                out[y:y + height, x:x + width] = tile
    return out
