"""The lab renderer: scene description, ray casting, wire sweeps with exact ground truth.

Modules
-------
raycast : vectorised numpy ray casting against a scene's objects; analytic wire occlusion.
render : render synthetic lab sweep captures with exact ground truth (direct illumination only).
scene : scene description for synthetic lab captures: geometry, materials, lights, cameras, wire sweeps.
sweeps : general wire sweeps (angle, motion, speed, plane, own light) and their exact ground truth.
virtual : virtual cameras of a sweep pair: perspective, orthographic, skewed, cross-slit.
"""
