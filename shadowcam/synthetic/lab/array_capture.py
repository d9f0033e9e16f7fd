"""A rendered virtual-camera-array capture from a manifest's ``synthetic:`` block.

The capture is the two experiments' frames, the images lit from each wire crossing and
the renderer's ground truth (:func:`shadowcam.synthetic.lab.light_motion.render_camera_array`),
plus the depth of each pixel's point beyond the mask plane, for the disparity law.

:func:`write_array_capture` writes it as a camera would, in the layout a user's camera-array
manifest declares (docs/contracts.md): ``horizontal/000000.<ext> ...`` (light moving along
e_u), ``vertical/...`` (along e_v), ``crossings/r<i>_c<j>.<ext>`` (lit from crossing (i, j)),
``ground_truth.nc`` (wire times, reciprocal views, depth) and ``capture.json``.

Offers
------
ARRAY_NOISE_INDEX : noise seed index of each image group (``[seed, index, image]``).
render_array_capture : ``synthetic`` block (with ``camera_array``) -> capture dataset.
write_array_capture : render and write the capture directory of a manifest's options.
"""

import datetime

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


#: noise seed index of each image group: ``numpy.random.default_rng([seed, index, image])``
ARRAY_NOISE_INDEX = {"horizontal": 20, "vertical": 21, "crossings": 22}
#: the frame variables of a rendered capture, by capture folder
_GROUPS = {"horizontal": "frames_horizontal", "vertical": "frames_vertical"}


def write_array_capture(options, out_dir):
    """Render a camera-array capture and write it as a capture directory.

    Parameters
    ----------
    options : dict
        :func:`shadowcam.synthetic.capture_options.capture_options` of a manifest whose
        ``synthetic`` block has ``camera_array``: ``format`` (dng or tiff), ``noise``,
        ``bit_depth``, ``exposure`` (the percentile of the brightest crossing-lit image
        exposed to that fraction of the range), ``seed``.
    out_dir : str or Path

    Returns
    -------
    Path
        `out_dir`, holding the frame files, ``ground_truth.nc`` (``t_vertical_wire``,
        ``t_horizontal_wire``, ``reciprocal``, ``depth``; attrs as
        :func:`render_array_capture`) and ``capture.json`` (top-level ``camera_array``).
    """
    import json
    from pathlib import Path

    from shadowcam import __version__
    from shadowcam._shared.atomic import atomic_directory
    from shadowcam._shared.progress import Progress
    from shadowcam.io.provenance import file_sha256
    from shadowcam.synthetic.capture_writer import CAPTURE_START, write_frame, write_ground_truth
    from shadowcam.synthetic.sensor import SensorModel, electrons_per_unit_radiance

    if not options.get("camera_array"):
        raise ValueError(f"options['camera_array']: capture {options.get('name')!r} has no camera_array "
                         "block; add camera_array: {rows, cols, spacing_frames} to the manifest's synthetic block")
    if options["light"] != "point":
        raise ValueError(f"manifest key 'light': the virtual camera array needs light: point; got "
                         f"{options['light']!r}")
    out_dir = Path(out_dir)
    capture = render_array_capture(options, light=options["light"])
    sensor = SensorModel(bit_depth=options["bit_depth"])
    brightest = capture["crossing_images"].values.max(axis=(0, 1))
    scale = electrons_per_unit_radiance(brightest, sensor=sensor, target_fraction=options["exposure"])
    ext, seed = options["format"], int(options["seed"])
    n, m = capture.sizes["camera_row"], capture.sizes["camera_col"]
    images = {folder: capture[var].values for folder, var in _GROUPS.items()}
    images["crossings"] = capture["crossing_images"].values.reshape(n * m, *capture["crossing_images"].shape[2:])
    names = {folder: [f"{folder}/{k:06d}.{ext}" for k in range(len(stack))] for folder, stack in images.items()}
    names["crossings"] = [f"crossings/r{i}_c{j}.{ext}" for i in range(n) for j in range(m)]
    progress = Progress(sum(len(v) for v in images.values()), "write camera-array images", unit="images")
    with atomic_directory(out_dir) as tmp:
        done = 0
        for folder, stack in images.items():
            (tmp / folder).mkdir()
            for k, (rel, radiance) in enumerate(zip(names[folder], stack)):
                write_frame(tmp / rel, radiance, frame_format=ext, noise=bool(options["noise"]), sensor=sensor,
                            scale=scale, seed=[seed, ARRAY_NOISE_INDEX[folder], k],
                            when=CAPTURE_START + datetime.timedelta(seconds=k))
                done += 1
                progress.update(done)
        checksums = {rel: file_sha256(tmp / rel) for group in names.values() for rel in group}
        truth = capture.drop_vars(["frames_horizontal", "frames_vertical", "crossing_images"])
        block = dict(options["camera_array"])
        write_ground_truth(tmp, truth, sensor=sensor, scale=scale, config=dict(options), checksums=checksums,
                           frame_format=ext, noise_seed="numpy.random.default_rng([seed, index, image]); "
                           + ", ".join(f"{k}={v}" for k, v in ARRAY_NOISE_INDEX.items()))
        description = {
            "name": options["name"], "kind": "lab", "description": options["description"], "light": "point",
            "root": ".",
            "sweeps": {folder: {"files": f"{folder}/*.{ext}"} for folder in _GROUPS},
            "timing": {"source": "rate", "rate_hz": 1.0},
            "checksums": checksums,
            "camera_array": {"rows": int(block["rows"]), "cols": int(block["cols"]),
                             "spacing_frames": float(block["spacing_frames"]),
                             "crossings": f"crossings/r{{row}}_c{{col}}.{ext}"},
            "ground_truth": {"format": "shadowcam_array_nc", "file": "ground_truth.nc",
                             "noise": "raw12" if options["noise"] else "noise_free"},
            "provenance": (f"rendered by shadowcam {__version__} 'shadowcam render-array' (scene "
                           f"{options['scene']}, seed {seed}, {options['height']}x{options['width']}, "
                           f"{n}x{m} wires, {ext} {options['bit_depth']}-bit, noise {options['noise']}); "
                           "deterministic"),
            "licence": "CC0-1.0",
        }
        (tmp / "capture.json").write_text(json.dumps(description, indent=2) + "\n")
    return out_dir
