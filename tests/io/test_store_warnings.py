"""Opening a frame store inside a workflow says nothing about Snakemake's own files."""

import warnings

import numpy as np

from shadowcam.io.frame_store import iter_frame_chunks, open_frames, write_frames


def test_snakemake_timestamp_inside_a_store_is_not_warned_about(tmp_path, make_frames):
    paths, expected = make_frames(tmp_path / "in", 4)
    out = write_frames(paths, tmp_path / "u.zarr", times_s=np.arange(4.0), chunk_frames=2)
    (out / ".snakemake_timestamp").touch()  # what Snakemake leaves in a directory output
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        store = open_frames(out)
        blocks = [block for _, block in iter_frame_chunks(store)]
    np.testing.assert_array_equal(np.concatenate(blocks), expected)
