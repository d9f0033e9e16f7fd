"""xarray datasets between the outdoor stages: assembly (dims, units, long names).

Provenance attrs are attached by the CLI step that writes each dataset;
encoding is left to the writer.

Offers
------
photometry_dataset : per-frame shifts and gains, per-pixel masks and levels.
photometry_arrays : the dict :class:`shadowcam.outdoor.tracking.EdgeTracker` takes, from that dataset.
photometry_part_dataset : one time part of the first pass (per-frame values, running minimum).
photometry_part_arrays : the dict :func:`shadowcam.outdoor.normalise.merge_parts` takes, from that dataset.
sky_mask_dataset : a sweep's sky mask and its source.
edges_dataset : tracked edges over (time, col), keyframes, interpolation flags.
pushbroom_dataset : the ridge pushbroom over (time, col, channel).
"""

import numpy as np
import xarray as xr

from shadowcam.outdoor.descent import RAMP_STATES
from shadowcam.outdoor.normalise import GAIN_SOURCES

_CHANNELS = np.array(["R", "G", "B"], dtype=object)


def _frame_coords(time_s, photometry=None):
    time_s = np.asarray(time_s, dtype=np.float64)
    coords = {
        "time": ("time", np.arange(time_s.size), {"units": "frame", "long_name": "frame index"}),
        "time_s": ("time", time_s, {"units": "s", "long_name": "frame time since the first frame"}),
    }
    if photometry is not None:
        shift = np.asarray(photometry["shift"])
        coords["shift_row"] = ("time", shift[:, 0], {"units": "pixel", "long_name": "estimated content shift along rows"})
        coords["shift_col"] = ("time", shift[:, 1], {"units": "pixel", "long_name": "estimated content shift along cols"})
        coords["gain"] = ("time", np.asarray(photometry["gain_lit"]),
                          {"units": "1", "long_name": "lit gain relative to the first frame (exposure x sun + sky)"})
    return coords


def photometry_dataset(result, time_s, *, exposure_gain=None, sky_source="auto"):
    """Assemble the first pass's result (:func:`shadowcam.outdoor.normalise.normalise_frames`).

    Returns
    -------
    xarray.Dataset
        ``gain_sky``, ``kept_lit``, ``gain_source``
        (:data:`shadowcam.outdoor.normalise.GAIN_SOURCES`), ``gain_median``, ``cloud_shade``
        (:func:`shadowcam.outdoor.normalise.cloud_shade`; not in a part), ``exposure_gain`` over ``time`` (coords
        ``time_s``, ``shift_row``, ``shift_col``, ``gain``); ``sky``,
        ``lit_at_start``, ``lit_level``, ``shadow_level`` over ``(row, col)``;
        ``shade_levels`` and ``shade_field`` (not in a part) over ``(time, block_row, block_col)`` with
        ``shade_rows``, ``shade_cols`` (:mod:`shadowcam.outdoor.shade_field`);
        ``reference (row, col, channel)``; attrs ``shadow_ratio``, ``sky_source``.
    """
    n_frames = len(result["gain_lit"])
    if np.size(time_s) != n_frames:
        raise ValueError(f"time_s has {np.size(time_s)} values for {n_frames} frames")
    exposure = np.full(n_frames, np.nan) if exposure_gain is None else np.asarray(exposure_gain, dtype=np.float64)
    cam = ("row", "col")
    data = {
        "gain_sky": ("time", np.asarray(result["gain_sky"]), {"units": "1", "long_name": "sky-light gain relative to the first frame"}),
        "kept_lit": ("time", np.asarray(result["kept_lit"]), {"units": "pixel", "long_name": "pixels used for the lit gain"}),
        "gain_source": ("time", np.asarray(result["gain_source"], dtype=np.int8),
                        {"units": "1", "long_name": "where the lit gain comes from",
                         "flag_values": np.array(list(GAIN_SOURCES), dtype=np.int8),
                         "flag_meanings": " ".join(name.replace(" ", "_") for name in GAIN_SOURCES.values())}),
        "gain_median": ("time", np.asarray(result["gain_median"]),
                        {"units": "1", "long_name": "median ratio frame / first frame of every lit pixel (follows a cloud)"}),
        "exposure_gain": ("time", exposure, {"units": "1", "long_name": "gain from exposure metadata (NaN unknown)"}),
        "sky": (cam, np.asarray(result["sky"], dtype=bool), {"long_name": "sky mask"}),
        "lit_at_start": (cam, np.asarray(result["lit_at_start"], dtype=bool), {"long_name": "sunlit in the first frame"}),
        "lit_level": (cam, result["lit_level"], {"units": "linear", "long_name": "luminance when lit, first-frame scale"}),
        "shadow_level": (cam, result["shadow_level"], {"units": "linear", "long_name": "luminance in shadow / gain_sky"}),
        "reference": (cam + ("channel",), result["reference"], {"units": "linear", "long_name": "first frame (reference of the registration)"}),
    }
    if "cloud_shade" in result:
        data["cloud_shade"] = ("time", np.asarray(result["cloud_shade"]),
                               {"units": "1", "long_name": "sun-term transmittance of a cloud over every lit pixel (1: none)"})
    blocks = ("time", "block_row", "block_col")
    if "shade_levels" in result:
        data["shade_levels"] = (blocks, np.asarray(result["shade_levels"], dtype=np.float32),
                                {"units": "1", "long_name": "brightest ratio frame / first frame of the lit pixels per "
                                 "block (NaN: none)"})
        data["shade_rows"] = ("block_row", np.asarray(result["shade_rows"], dtype=np.float64),
                              {"units": "pixel", "long_name": "block centre row (pixel centres at i + 0.5)"})
        data["shade_cols"] = ("block_col", np.asarray(result["shade_cols"], dtype=np.float64),
                              {"units": "pixel", "long_name": "block centre column"})
    if "shade_field" in result:
        data["shade_field"] = (blocks, np.asarray(result["shade_field"], dtype=np.float32),
                               {"units": "1", "long_name": "sun-term transmittance of a cloud per block (1: none)"})
    coords = _frame_coords(time_s, result)
    coords["channel"] = _CHANNELS[: np.shape(result["reference"])[2]]
    dataset = xr.Dataset(data, coords=coords)
    dataset.attrs.update(shadow_ratio=float(result["shadow_ratio"]), sky_source=str(sky_source))
    return dataset


def photometry_arrays(dataset):
    """Return the arrays of a photometry dataset as the dict the tracking pass takes."""
    return {
        "shift": np.stack([dataset["shift_row"].values, dataset["shift_col"].values], axis=1),
        "gain_lit": dataset["gain"].values,
        "gain_sky": dataset["gain_sky"].values,
        "cloud_shade": dataset["cloud_shade"].values if "cloud_shade" in dataset else None,
        **({key: dataset[key].values for key in ("shade_field", "shade_rows", "shade_cols")}
           if "shade_field" in dataset else {}),
        "sky": dataset["sky"].values.astype(bool),
        "lit_at_start": dataset["lit_at_start"].values.astype(bool),
        "lit_level": dataset["lit_level"].values,
        "shadow_level": dataset["shadow_level"].values,
        "shadow_ratio": dataset.attrs.get("shadow_ratio"),
    }


def photometry_part_dataset(part, time_s, *, exposure_gain=None, sky_source="auto"):
    """Assemble one time part of the first pass (:func:`shadowcam.outdoor.normalise.normalise_part`).

    Parameters
    ----------
    part : dict
        :meth:`shadowcam.outdoor.normalise.SequenceNormaliser.partial`.
    time_s : (T_part,) ndarray
        Times of the part's frames, seconds.
    exposure_gain : (T_part,) ndarray, optional
    sky_source : str, optional

    Returns
    -------
    xarray.Dataset
        Over ``time`` (the part's frame indices): coords ``time_s``, ``shift_row``,
        ``shift_col``, ``gain``; ``gain_sky``, ``kept_lit``, ``gain_source``, ``gain_median``, ``exposure_gain``; over
        ``(row, col)``: ``shadow_min`` (linear), ``sky``, ``lit_at_start``;
        ``reference (row, col, channel)`` only in the part holding frame 0.
        Attrs ``first_frame``, ``sky_source``, ``white_level`` (decoded; NaN: none known).
    """
    n_frames = len(part["gain_lit"])
    first = int(part["first_frame"])
    result = {**part, "shadow_ratio": np.nan, "lit_level": part["shadow_min"], "shadow_level": part["shadow_min"]}
    dataset = photometry_dataset(result, time_s, exposure_gain=exposure_gain, sky_source=sky_source)
    dataset = dataset.drop_vars(["lit_level", "shadow_level"]).assign_coords(time=np.arange(first, first + n_frames))
    dataset["shadow_min"] = (("row", "col"), part["shadow_min"],
                             {"units": "linear", "long_name": "minimum of 3-frame smoothed luminance / gain_sky over the part"})
    if first != 0:
        dataset = dataset.drop_vars(["reference", "channel"])
    dataset.attrs.update(first_frame=first, white_level=float(part.get("white_level", np.nan)))
    del dataset.attrs["shadow_ratio"]
    return dataset


def photometry_part_arrays(dataset):
    """Return a part dataset (:func:`photometry_part_dataset`) as the dict ``merge_parts`` takes."""
    return {
        "first_frame": int(dataset.attrs["first_frame"]),
        "shift": np.stack([dataset["shift_row"].values, dataset["shift_col"].values], axis=1),
        "gain_lit": dataset["gain"].values,
        "gain_sky": dataset["gain_sky"].values,
        "kept_lit": dataset["kept_lit"].values,
        "gain_source": dataset["gain_source"].values,
        "gain_median": dataset["gain_median"].values,
        "shade_levels": dataset["shade_levels"].values,
        "shade_rows": dataset["shade_rows"].values,
        "shade_cols": dataset["shade_cols"].values,
        "shadow_min": dataset["shadow_min"].values,
        "sky": dataset["sky"].values.astype(bool),
        "lit_at_start": dataset["lit_at_start"].values.astype(bool),
        "reference": dataset["reference"].values if "reference" in dataset else None,
        "white_level": float(dataset.attrs.get("white_level", np.nan)),
    }


def sky_mask_dataset(mask, *, source):
    """A sweep's sky mask as a dataset.

    Parameters
    ----------
    mask : (rows, cols) bool ndarray
    source : str
        How it was obtained (``auto`` or the manifest override), attr ``sky_source``.

    Returns
    -------
    xarray.Dataset
        ``sky_mask (row, col)`` uint8 (1 = sky).
    """
    mask = np.asarray(mask, dtype=bool)
    if mask.ndim != 2:
        raise ValueError(f"mask must be (rows, cols); got shape {mask.shape}")
    return xr.Dataset({"sky_mask": (("row", "col"), mask.astype(np.uint8), {"long_name": "sky (1) or scene (0)"})},
                      attrs={"sky_source": str(source)})


def edges_dataset(tracked, photometry, time_s, *, edge_row, is_keyframe, interpolated):
    """Assemble the tracked edges.

    Parameters
    ----------
    tracked : mapping
        Result of :func:`shadowcam.outdoor.tracking.track_frames`.
    photometry : mapping
        :func:`photometry_arrays` (for the shift and gain coords).
    time_s : (T,) ndarray
    edge_row : (T, W) ndarray
        Final edges after keyframe interpolation.
    is_keyframe : (T,) bool ndarray
    interpolated : (T, W) bool ndarray

    Returns
    -------
    xarray.Dataset
        ``edge_row``, ``edge_row_measured``, ``confidence``, ``n_transitions``,
        ``interpolated`` over ``(time, col)``; ``is_keyframe``, ``band_fraction``
        over ``time``; ``coverage_arrival_s``, ``n_events`` over ``(row, col)`` and
        ``event_start_s``, ``event_end_s``, ``event_depth`` over ``(row, col, event_slot)``
        (the earlier dark episodes, when `tracked` has them); ``ramp_centre_s``,
        ``ramp_duration_s``, ``ramp_sigma_s``, ``ramp_state`` (CF flags) over ``(row, col)``
        (the fitted final descent, when `tracked` has it).
    """
    tc = ("time", "col")
    rows = "pixel-edge coordinates: row r spans [r, r+1], centre r+0.5; lit above"
    data = {
        "edge_row": (tc, np.asarray(edge_row, np.float32),
                     {"units": "pixel", "long_name": "shadow-edge row after keyframe interpolation", "comment": rows}),
        "edge_row_measured": (tc, tracked["edge_row"], {"units": "pixel", "long_name": "shadow-edge row as measured", "comment": rows}),
        "confidence": (tc, tracked["confidence"], {"units": "1", "long_name": "edge confidence (step-model fit)"}),
        "n_transitions": (tc, tracked["n_transitions"], {"long_name": "lit-above / shadowed-below pairs in the column"}),
        "interpolated": (tc, np.asarray(interpolated, bool), {"long_name": "edge interpolated between keyframes"}),
        "is_keyframe": ("time", np.asarray(is_keyframe, bool), {"long_name": "frame whose edge is reliable"}),
        "band_fraction": ("time", tracked["band_fraction"], {"units": "1", "long_name": "share of valid pixels in the frame-differencing band"}),
        "coverage_arrival_s": (("row", "col"), tracked["coverage_arrival_s"],
                               {"units": "s", "long_name": "start of the pixel's final dark episode "
                                "(lit fraction below 0.5, never relit after)"}),
    }
    if "n_events" in tracked:
        slot = ("row", "col", "event_slot")
        data.update({
            "final_depth": (("row", "col"), tracked["final_depth"], {"units": "1", "long_name": "1 - mean lit fraction during the final dark episode"}),
            "n_events": (("row", "col"), tracked["n_events"], {"long_name": "dark episodes before the final one (relit after)"}),
            "event_start_s": (slot, tracked["event_start_s"], {"units": "s", "long_name": "start of an earlier dark episode"}),
            "event_end_s": (slot, tracked["event_end_s"], {"units": "s", "long_name": "end (relighting) of an earlier dark episode"}),
            "event_depth": (slot, tracked["event_depth"], {"units": "1", "long_name": "1 - mean lit fraction during the episode"}),
        })
    if "ramp_state" in tracked:
        cam = ("row", "col")
        codes = sorted(RAMP_STATES)
        data.update({
            "ramp_centre_s": (cam, tracked["ramp_centre_s"], {"units": "s", "long_name": "centre of the fitted penumbra ramp (half the sun occluded)"}),
            "ramp_duration_s": (cam, tracked["ramp_duration_s"], {"units": "s", "long_name": "duration of the penumbra ramp"}),
            "ramp_sigma_s": (cam, tracked["ramp_sigma_s"], {"units": "s", "long_name": "standard error of the ramp centre (fit residual)"}),
            "ramp_state": (cam, np.asarray(tracked["ramp_state"], np.uint8), {
                "long_name": "how the final descent's ramp was fitted", "flag_values": np.array(codes, np.uint8),
                "flag_meanings": " ".join(RAMP_STATES[c] for c in codes)}),
        })
    return xr.Dataset(data, coords=_frame_coords(time_s, photometry))



def pushbroom_dataset(pushbroom, edge_row, time_s):
    """Assemble the ridge pushbroom ``(time, col, channel)`` with the edge row as a coord."""
    pushbroom = np.asarray(pushbroom)
    coords = _frame_coords(time_s)
    coords["channel"] = _CHANNELS[: pushbroom.shape[2]]
    coords["edge_row"] = (("time", "col"), np.asarray(edge_row, np.float32), {"units": "pixel", "long_name": "sampled edge row"})
    data = {"pushbroom": (("time", "col", "channel"), pushbroom, {
        "units": "linear", "long_name": "ridge pushbroom: first-frame colour along the shadow edge of each frame",
        "comment": "row k = frame k at time_s[k]; column = image column; linear between the two pixel "
                   "centres straddling the edge; NaN where the column has no edge"})}
    return xr.Dataset(data, coords=coords)
