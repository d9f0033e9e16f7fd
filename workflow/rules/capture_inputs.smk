# Input functions of the camera-array stage (workflow/rules/array.smk), from the capture
# plan of a camera-array manifest (captured, or rendered into results/<ds>/array/capture).


def array_manifest(wildcards):
    """The camera-array manifest: the rendered capture.json, or the dataset's own manifest."""
    if capture(wildcards.ds).rendered:
        return f"results/{wildcards.ds}/array/capture/capture.json"
    return f"data_manifest/{wildcards.ds}.yaml"


def array_ground_truth(wildcards):
    """ground_truth.nc of a camera-array capture (rendered, or the manifest's ground_truth)."""
    plan = capture(wildcards.ds)
    if plan.rendered:
        return f"results/{wildcards.ds}/array/capture/ground_truth.nc"
    return plan.camera_array["ground_truth"]
