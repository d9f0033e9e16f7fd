"""Lab sweeps: per-pixel shadow times of a moving wire's shadow (streaming dip tracking,
sub-frame estimators, edge-aware refinement), resolution planning and accuracy.

Modules
-------
accuracy : accuracy of shadow times, dual coordinates and dual views against ground truth.
dip_kernels : compiled per-pixel kernels of the streaming dip tracker (numba).
dip_tracker : streaming per-pixel tracking of the deepest intensity dip of a sweep.
edge_refine : edge-aware spatial refinement of per-pixel shadow times.
mosaic_signal : the dip tracker's signal straight from a Bayer mosaic, without demosaicking each frame.
planning : resolution planning of a shadow-camera capture (paper section II-B, Eq. 3).
shadow_time : per-pixel shadow time of a sweep: when the mask's shadow passes each pixel.
sweep_files : shadow times straight from a sweep's image files, decoding and tracking on every core.
"""
