"""Frame differencing (paper section VII): where can the shadow edge be in a frame?

Between two consecutive frames only the pixels the shadow edge swept over
change their lit fraction; everything else (after photometric normalisation)
stays put. The pixels whose coverage dropped, widened by a small margin, form
the band in which the edge of the later frame is searched.

Offers
------
difference_band : pixels whose coverage dropped between two frames, widened.
"""

import cv2
import numpy as np

from shadowcam._shared.validation import check_positive


def difference_band(previous, current, *, valid=None, min_drop=0.2, margin=2):
    """Return the band where the shadow edge moved between two frames.

    Parameters
    ----------
    previous, current : (H, W) ndarray
        Coverage (lit fraction) of two consecutive frames.
    valid : (H, W) bool ndarray, optional
        Pixels that can hold the edge (not sky).
    min_drop : float, optional
        Minimum drop of coverage for a pixel to count as newly shadowed.
    margin : int, optional
        Rows (and columns) by which the changed pixels are widened.

    Returns
    -------
    (H, W) bool ndarray
    """
    prev = np.asarray(previous, dtype=np.float32)
    curr = np.asarray(current, dtype=np.float32)
    if prev.shape != curr.shape or prev.ndim != 2:
        raise ValueError(f"previous {prev.shape} and current {curr.shape} must be the same (H, W) shape")
    check_positive(min_drop, "min_drop")
    with np.errstate(invalid="ignore"):
        drop = (prev - curr) >= np.float32(min_drop)  # NaN never counts as a drop
    if valid is not None:
        drop &= np.asarray(valid, dtype=bool)
    size = 2 * int(margin) + 1
    return cv2.dilate(drop.astype(np.uint8), np.ones((size, size), np.uint8)) > 0
