"""The lab renderer: scene description, ray casting, wire sweeps with exact ground truth.

Modules
-------
edges : exact image positions of straight scene edges (the back plane's coloured squares).
optics : optical elements on the camera's side only: mirrors and thick glass that bend primary rays.
raycast : vectorised numpy ray casting against a scene's objects; analytic wire occlusion.
render : render synthetic lab sweep captures with exact ground truth (direct illumination only).
scene : scene description for synthetic lab captures: geometry, materials, lights, cameras, wire sweeps.
sweeps : general wire sweeps (angle, motion, speed, plane, own light) and their exact ground truth.
virtual : virtual cameras of a sweep pair: perspective, orthographic, skewed, cross-slit.
"""
