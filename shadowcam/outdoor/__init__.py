"""Outdoor time-lapses: registration, photometry, sky masks, frame differencing, shadow-edge
tracking with keyframes, arrival times, and their accuracy.

Modules
-------
accuracy : accuracy of outdoor arrival-time maps against ground truth, and the naive baseline.
arrival : per-pixel shadow-arrival time (seconds, sub-frame) from tracked edges.
datasets : xarray datasets between the outdoor stages: assembly (dims, units, long names).
edge_tracking : shadow-edge tracking: the edge curve of one frame, column by column, sub-pixel.
frame_difference : frame differencing (paper section VII): where can the shadow edge be in a frame?.
keyframes : keyframes of the tracked edge, and interpolation of the edge between them.
normalise : first streaming pass over an outdoor time-lapse: registration, gains, levels.
photometric : photometric normalisation of an outdoor time-lapse.
registration : sub-pixel registration of time-lapse frames to a reference frame.
sky_mask : sky masks of outdoor views: automatic, or from a manifest polygon or mask image.
strips : the outdoor edge-tracking pass in column strips, merged exactly.
tracking : second streaming pass over an outdoor time-lapse: coverage, edges, crossings.
translation : sub-pixel translation of an image whose result does not depend on where the image is cut.
"""
