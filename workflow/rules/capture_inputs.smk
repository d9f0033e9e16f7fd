# Input functions of the stages that read a capture's files through its manifest: the
# camera array (workflow/rules/array.smk: folder "array", plan.camera_array) and several
# lights (workflow/rules/lights.smk: folder "lights", plan.light_set). The capture is a
# user's (data_manifest/<ds>.yaml) or rendered into results/<ds>/<folder>/capture.


def capture_manifest(folder):
    """Input function: the rendered capture.json under `folder`, or the dataset's manifest."""

    def manifest(wildcards):
        if capture(wildcards.ds).rendered:
            return f"results/{wildcards.ds}/{folder}/capture/capture.json"
        return f"data_manifest/{wildcards.ds}.yaml"

    return manifest


def capture_ground_truth(folder, block):
    """Input function: ground_truth.nc, rendered under `folder` or the plan's `block` names."""

    def ground_truth(wildcards):
        plan = capture(wildcards.ds)
        if plan.rendered:
            return f"results/{wildcards.ds}/{folder}/capture/ground_truth.nc"
        return getattr(plan, block)["ground_truth"]

    return ground_truth
