"""Option parsing shared by the command-line steps.

Offers
------
parse_params : the ``--params`` JSON object, checked against the allowed keys.
parse_frame_range : a ``START:STOP`` frame range inside a sweep, on a chunk boundary.
parse_part : a ``START:STOP`` time part of a frame store (``START:`` = to the end).
parse_strip : an ``I/N`` column strip.
"""

import json


def parse_params(text, *, allowed=None):
    """Parse a ``--params`` JSON string into a dict.

    Parameters
    ----------
    text : str
        JSON object text.
    allowed : iterable of str, optional
        Keys the step understands; any other key raises.

    Returns
    -------
    dict

    Raises
    ------
    ValueError
        When the text is not a JSON object or names an unknown key.
    """
    try:
        params = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ValueError(f"--params is not valid JSON: {exc}") from None
    if not isinstance(params, dict):
        raise ValueError(f"--params must be a JSON object, got {text!r}")
    if allowed is not None:
        unknown = set(params) - set(allowed)
        if unknown:
            raise ValueError(f"--params: unknown keys {sorted(unknown)}; allowed {sorted(allowed)}")
    return params


def parse_frame_range(text, n_frames, *, chunk_frames=None, option="--frames"):
    """Return ``(start, stop)`` of a ``START:STOP`` range inside a sweep of `n_frames`.

    `stop` is clipped to `n_frames` (the workflow sizes the last part by the
    nominal job length); `start` must lie inside the sweep and, with
    `chunk_frames`, on a chunk boundary.
    """
    try:
        start, stop = (int(v) for v in text.split(":"))
    except ValueError:
        raise ValueError(f"{option} must be START:STOP with integers, got {text!r}") from None
    if not 0 <= start < n_frames or stop <= start:
        raise ValueError(f"{option} {text}: need 0 <= START < {n_frames} (frames in the sweep) and STOP > START")
    if chunk_frames is None or start % chunk_frames:
        raise ValueError(f"{option} {text}: START must be a multiple of --chunk-frames (given: {chunk_frames})")
    return start, min(stop, n_frames)


def parse_part(text, n_frames, *, option="--part"):
    """Return ``(start, stop)`` of a ``START:STOP`` part of `n_frames` frames (``START:`` = to the end)."""
    try:
        start, stop = text.split(":")
        start, stop = int(start), (int(stop) if stop else n_frames)
    except ValueError:
        raise ValueError(f"{option} must be START:STOP (frame indices); got {text!r}") from None
    if not 0 <= start < stop <= n_frames:
        raise ValueError(f"{option} {text}: need 0 <= START < STOP <= {n_frames} (frames in the store)")
    return start, stop


def parse_strip(text, *, option="--strip"):
    """Return ``(index, count)`` of an ``I/N`` strip argument."""
    try:
        index, count = (int(v) for v in text.split("/"))
    except ValueError:
        raise ValueError(f"{option} must be I/N (e.g. 0/3); got {text!r}") from None
    if not 0 <= index < count:
        raise ValueError(f"{option} {text}: I must be in [0, N)")
    return index, count

