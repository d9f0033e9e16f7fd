"""Files in and out: capture manifests, frame decoding (RAW, PNG, TIFF, EXR), frame stores,
datasets with provenance, ground-truth loaders and writers of rendered frames.

Modules
-------
capture_plan : every fact the workflow plans jobs from (files, frame counts, shape, dual model), once.
cfa : colour filter arrays (Bayer mosaics): patterns, per-site constants, bilinear demosaic.
decode : frame decoding: camera RAW, TIFF, PNG and EXR to linear float32 RGB.
frame_store : time-chunked frame stores (zarr v3): write decoded frames, open and stream them.
frame_times : frame times of a time-lapse: the source preference order, intervals and gaps.
ground_truth : ground truth of synthetic captures in the standard form (docs/contracts.md).
images : image and dataset writers: linear EXR, 8-bit PNG previews, NetCDF, all atomic.
manifest : capture descriptions (manifests): load, validate, resolve files and times, checksums.
mosaic_reader : A sweep's Bayer mosaics, read fast: DNG raw data straight from the TIFF structure, checked against rawpy.
provenance : provenance: file checksums, config digests and dataset attributes.
raw_mosaic : camera RAW files through rawpy (LibRaw): which files are RAW, and their Bayer mosaic.
raw_writer : writers for rendered frames: RGGB Bayer DNG and 16-bit linear RGB TIFF.
"""
