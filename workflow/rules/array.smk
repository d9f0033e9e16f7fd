# Stage: the virtual camera array (datasets whose manifest has camera_array, captured, or
# synthetic.camera_array, rendered): a rendered array is written as a capture folder
# (frame files, crossing images, capture.json, ground_truth.nc); each pixel's dips are
# assigned to the wires and one view is built per wire crossing from the capture's files,
# then scored against the ground truth (accuracy.json) and drawn beside the reciprocal
# renders (views.png, the paper's Fig. 6).


rule array_render:
    input:
        "data_manifest/{ds}.yaml",
    output:
        capture="results/{ds}/array/capture/capture.json",
        truth="results/{ds}/array/capture/ground_truth.nc",
    log:
        "logs/{ds}/array_render.log",
    benchmark:
        "benchmarks/{ds}/array_render.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_array_mem_mb,
        runtime=30,
    shell:
        "shadowcam render-array --manifest {input} --out results/{wildcards.ds}/array/capture"
        " > {log} 2>&1"


rule camera_array:
    input:
        capture_manifest("array"),
    output:
        "results/{ds}/array/camera_array.nc",
    log:
        "logs/{ds}/camera_array.log",
    benchmark:
        "benchmarks/{ds}/camera_array.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_array_mem_mb,
        runtime=30,
    shell:
        "shadowcam camera-array --manifest {input} --out {output} > {log} 2>&1"


rule array_accuracy:
    input:
        truth=capture_ground_truth("array", "camera_array"),
        array="results/{ds}/array/camera_array.nc",
    output:
        json="results/{ds}/array/accuracy.json",
        png=report(
            "results/{ds}/array/views.png",
            caption="../report/camera_array.rst",
            category="Camera array",
        ),
    log:
        "logs/{ds}/array_accuracy.log",
    benchmark:
        "benchmarks/{ds}/array_accuracy.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_array_mem_mb,
        runtime=15,
    shell:
        "shadowcam array-accuracy --ground-truth {input.truth} --array {input.array}"
        " --out-json {output.json} --out-png {output.png} > {log} 2>&1"
