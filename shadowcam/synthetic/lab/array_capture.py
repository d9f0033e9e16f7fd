"""A rendered virtual-camera-array capture from a manifest's ``synthetic:`` block.

The capture is the two experiments' frames, the images lit from each wire crossing and
the renderer's ground truth (:func:`shadowcam.synthetic.lab.light_motion.render_camera_array`),
plus the depth of each pixel's point beyond the mask plane, for the disparity law.

Offers
------
render_array_capture : ``synthetic`` block (with ``camera_array``) -> capture dataset.
"""

import numpy as np

from shadowcam.synthetic.lab.light_motion import render_camera_array
from shadowcam.synthetic.lab.render import pixel_centre_ground_truth
from shadowcam.synthetic.lab.scenes import make_scene


def render_array_capture(synthetic, *, light="point"):
    """Render the camera-array capture a manifest describes.

    Parameters
    ----------
    synthetic : mapping
        The manifest's ``synthetic`` block: ``scene``, ``seed``, ``height``, ``width``,
        ``frames``, optional ``supersample`` and ``camera_array`` (``rows``, ``cols``,
        ``spacing_frames``, optional ``radius_frames``).
    light : str
        The manifest's ``light`` (the array needs ``point``).

    Returns
    -------
    xarray.Dataset
        As :func:`~shadowcam.synthetic.lab.light_motion.render_camera_array`, plus
        ``depth`` (y, x): distance of each pixel-centre point beyond the mask plane (NaN
        where the ray misses), and attrs ``spacing_frames``, ``radius_frames``.
    """
    if "camera_array" not in synthetic:
        raise ValueError("synthetic: no camera_array block; add camera_array: {rows, cols, "
                         "spacing_frames} to the manifest's synthetic block")
    array = synthetic["camera_array"]
    scene = make_scene(synthetic["scene"], seed=int(synthetic["seed"]), height=int(synthetic["height"]),
                       width=int(synthetic["width"]), frames=int(synthetic["frames"]), light_kind=light)
    spacing = float(array["spacing_frames"])
    radius = float(array.get("radius_frames", 0.6))
    capture = render_camera_array(scene, n_rows=int(array["rows"]), n_cols=int(array["cols"]),
                                  spacing_frames=spacing, radius_frames=radius,
                                  supersample=int(synthetic.get("supersample", 3)))
    centre = pixel_centre_ground_truth(scene.objects, scene.camera, scene.light, scene.mask, {})
    depth = (centre["P"] - scene.mask.origin) @ scene.mask.normal
    capture["depth"] = (("y", "x"), np.where(centre["hit"], depth, np.nan))
    capture.attrs.update(spacing_frames=spacing, radius_frames=radius)
    return capture
