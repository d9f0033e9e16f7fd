# Stages: dual coordinates (u, v per camera pixel) and the dual view (the scene seen
# from the light) resampled onto the dual grid.


rule dual_coords:
    input:
        shadow_time="results/{ds}/shadow_time.nc",
        capture=get_capture_input,
    output:
        "results/{ds}/dual_coords.nc",
    log:
        "logs/{ds}/dual_coords.log",
    benchmark:
        "benchmarks/{ds}/dual_coords.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_image_mem_mb,
        runtime=15,
    params:
        manifest=get_capture_manifest,
        model=get_dual_model,
        options=get_dual_coords_params,
    shell:
        "shadowcam dual-coords --shadow-time {input.shadow_time} --manifest {params.manifest}"
        " --model {params.model} --params {params.options:q} --out {output} > {log} 2>&1"


rule dual_view:
    input:
        dual_coords="results/{ds}/dual_coords.nc",
        shadow_time="results/{ds}/shadow_time.nc",
        reference=get_reference,
    output:
        nc="results/{ds}/dual_view.nc",
        exr="results/{ds}/dual_view.exr",
        png="results/{ds}/dual_view.png",
    log:
        "logs/{ds}/dual_view.log",
    benchmark:
        "benchmarks/{ds}/dual_view.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_image_mem_mb,
        runtime=15,
    params:
        reference=get_flag("--reference", "reference"),
        method=config["dual_view"]["method"],
        options=get_dual_view_params,
        intrinsics=as_json(config["dual_view"]["intrinsics"]),
    shell:
        "shadowcam dual-view --dual-coords {input.dual_coords} --shadow-time {input.shadow_time}"
        " {params.reference} --method {params.method} --params {params.options:q}"
        " --intrinsics {params.intrinsics:q} --out {output.nc} --exr {output.exr}"
        " --png {output.png} > {log} 2>&1"
