"""``shadowcam plan``: dual resolution of a planned capture and the mask speed for a wanted one.

Lengths are in metres and times in seconds (any one length unit works, if all
lengths use it; the mask speed is then that unit per second).

Example::

    shadowcam plan --pixel-width 5.9e-6 --mask-distance 0.3 --depth 2.0 \\
        --focal-length 0.035 --frame-time 0.04 --image-pixels 4000 --wanted-dual-pixels 500

Prints the paper's Eq. 3 (section II-B): r = W h (D - f) / (f D u t) dual pixels per
camera pixel, the dual pixels and frames per sweep, and the recommended mask speed.

Offers
------
add_parser : register the step and its options.
run : evaluate and print the plan.
"""

import re

#: the library's parameter names, which errors name, and this step's flags for them
_FLAGS = re.compile(r"\b(pixel_width|mask_distance|depth|focal_length|frame_time|image_pixels|mask_speed"
                    r"|wanted_dual_pixels)\b")


def add_parser(subparsers, name):
    """Register ``plan`` on `subparsers`; return its parser."""
    parser = subparsers.add_parser(name, help="resolution planning (paper Eq. 3)")
    parser.add_argument("--pixel-width", type=float, required=True, help="W, width of one sensor pixel, metres (e.g. 5.9e-6)")
    parser.add_argument("--mask-distance", type=float, required=True,
                        help="h, distance from the light to the mask, metres")
    parser.add_argument("--depth", type=float, required=True, help="D, greatest scene depth (from the camera), metres")
    parser.add_argument("--focal-length", type=float, required=True, help="f, focal length of the camera lens, metres (e.g. 0.035)")
    parser.add_argument("--frame-time", type=float, required=True,
                        help="t, time between frames, seconds (the mask moves u t metres per frame)")
    parser.add_argument("--image-pixels", type=int, required=True,
                        help="camera pixels across the swept direction (count, e.g. 4000)")
    parser.add_argument("--mask-speed", type=float, default=None, help="u, planned mask speed, metres per second")
    parser.add_argument("--wanted-dual-pixels", type=float, default=None,
                        help="wanted dual pixels across the sweep (count); prints the mask speed for it")
    return parser


def run(args):
    """Print the plan."""
    from shadowcam.lab.planning import plan_capture

    try:
        plan = plan_capture(pixel_width=args.pixel_width, mask_distance=args.mask_distance,
                            depth=args.depth, focal_length=args.focal_length,
                            frame_time=args.frame_time, image_pixels=args.image_pixels,
                            mask_speed=args.mask_speed, wanted_dual_pixels=args.wanted_dual_pixels)
    except ValueError as exc:  # name the flags the user typed, not the library's parameters
        raise ValueError(_FLAGS.sub(lambda m: "--" + m[1].replace("_", "-"), str(exc))) from None
    if "ratio" in plan:
        print(f"mask speed u = {plan['mask_speed']:.6g} metres per second")
        print(f"  r = {plan['ratio']:.4g} dual pixels per camera pixel (Eq. 3)")
        print(f"  dual resolution across the sweep = {plan['dual_pixels']:.1f} pixels "
              f"({plan['frames_per_sweep']:.1f} frames for the shadow to cross the image)")
        if plan["exceeds_camera"]:
            print("  warning: r > 1, the dual view asks for more pixels than the camera "
                  "resolves (holes); move the mask faster")
    if "recommended_mask_speed" in plan:
        print(f"for {plan['wanted_dual_pixels']:.0f} dual pixels across "
              f"{plan['image_pixels']} camera pixels (r = {plan['recommended_ratio']:.4g}):")
        print(f"  recommended mask speed u = {plan['recommended_mask_speed']:.6g} metres per second "
              f"({plan['mask_step_per_frame']:.6g} metres per frame)")
        if plan["recommended_exceeds_camera"]:
            print("  warning: more dual pixels than camera pixels (r > 1): the dual view "
                  "will have holes")
