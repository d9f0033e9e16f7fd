# Stage: the virtual camera array (datasets whose manifest has synthetic.camera_array):
# render the grid-mask capture, assign each pixel's dips to the wires and build one view
# per wire crossing, then score it against the renderer's ground truth (accuracy.json)
# and draw the views beside their reciprocal renders (views.png, the paper's Fig. 6).


rule array_render:
    input:
        "data_manifest/{ds}.yaml",
    output:
        "results/{ds}/array/capture.nc",
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
        "shadowcam render-array --manifest {input} --out {output} > {log} 2>&1"


rule camera_array:
    input:
        "results/{ds}/array/capture.nc",
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
        "shadowcam camera-array --capture {input} --out {output} > {log} 2>&1"


rule array_accuracy:
    input:
        capture="results/{ds}/array/capture.nc",
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
        "shadowcam array-accuracy --capture {input.capture} --array {input.array}"
        " --out-json {output.json} --out-png {output.png} > {log} 2>&1"
