"""The virtual camera array beside its ground truth (paper Fig. 6 layout).

Offers
------
array_figure : each camera's view (left block) and the reciprocal render of the same
    crossing (right block), cameras in their array rows and columns, on labelled dual axes.
"""

import numpy as np

from shadowcam.io.images import tone_map, white_point
from shadowcam.report.figures import DUAL_AXES, WHITE_PERCENTILE, _new_figure, _small_panel

#: inches per panel side (before the longer dual axis sets its aspect)
_PANEL_INCHES = 1.9


def array_figure(views, reciprocal, *, size=None):
    """Figure of the array's views and their reciprocal renders, in the array's layout.

    Each block (the estimated views, the reciprocal renders) has one white point over all
    its cameras, so brightness compares across cameras within a block; the two blocks
    differ photometrically (camera and light fall-off swap), so each has its own.

    Parameters
    ----------
    views : (n, m, V, U, C) array_like
        Estimated views of the ``n x m`` cameras on the dual grid (NaN = hole, drawn in the
        hole colour).
    reciprocal : (n, m, V, U, C) array_like
        Ground-truth views of the same cameras on the same grid.
    size : (float, float), optional
        Figure width, height in inches; default :data:`_PANEL_INCHES` per panel.

    Returns
    -------
    matplotlib.figure.Figure
        ``n`` rows of ``2 m`` panels: the ``m`` estimated views, then the ``m`` reciprocal
        renders; panel ``(i, j)`` of each block is camera ``(i, j)`` (wire crossing i, j).
    """
    views, reciprocal = np.asarray(views, np.float64), np.asarray(reciprocal, np.float64)
    if views.shape != reciprocal.shape or views.ndim != 5:
        raise ValueError(f"views and reciprocal must both be (n, m, V, U, C); got {views.shape} and "
                         f"{reciprocal.shape}")
    n, m, height, width = views.shape[:4]
    aspect = height / width
    figure = _new_figure(size or (2 * m * _PANEL_INCHES + 0.6, n * _PANEL_INCHES * max(aspect, 0.5) + 0.9))
    blocks = (("camera", views), ("reciprocal", reciprocal))
    for block, (label, images) in enumerate(blocks):
        scale = white_point(images.reshape(-1, 1, images.shape[-1]), percentile=WHITE_PERCENTILE)
        for i in range(n):
            for j in range(m):
                _small_panel(figure.add_subplot(n, 2 * m, i * 2 * m + block * m + j + 1),
                             tone_map(images[i, j], scale=scale), f"{label} ({i}, {j})",
                             xlabel=DUAL_AXES[0] if i == n - 1 else None, ylabel=DUAL_AXES[1] if j == 0 else None)
    figure.suptitle("virtual camera array: views from the shadows (left), reciprocal renders (right)",
                    fontsize="medium")
    figure.tight_layout(rect=(0, 0, 1, 0.95))
    return figure
