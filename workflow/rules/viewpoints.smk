# Stage: dual views from points across each pixel's dip interval (config
# dual_view.viewpoints): the shadow times at the viewpoint (viewpoint_shadow_time), then
# the dual stages of dual.smk on them. The accuracy step scores each viewpoint's products
# (targets.smk: get_viewpoint_products) against its reciprocal render, when the ground truth has one.


rule viewpoint_shadow_time:
    input:
        "results/{ds}/shadow_time.nc",
    output:
        "results/{ds}/viewpoints/{viewpoint}/shadow_time.nc",
    log:
        "logs/{ds}/viewpoint_{viewpoint}_shadow_time.log",
    benchmark:
        "benchmarks/{ds}/viewpoint_{viewpoint}_shadow_time.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_image_mem_mb,
        runtime=15,
    shell:
        "shadowcam viewpoint --shadow-time {input} --viewpoint {wildcards.viewpoint}"
        " --out {output} > {log} 2>&1"


use rule dual_coords as viewpoint_dual_coords with:
    input:
        shadow_time="results/{ds}/viewpoints/{viewpoint}/shadow_time.nc",
        capture=get_capture_input,
    output:
        "results/{ds}/viewpoints/{viewpoint}/dual_coords.nc",
    log:
        "logs/{ds}/viewpoint_{viewpoint}_dual_coords.log",
    benchmark:
        "benchmarks/{ds}/viewpoint_{viewpoint}_dual_coords.tsv"


use rule dual_view as viewpoint_dual_view with:
    input:
        dual_coords="results/{ds}/viewpoints/{viewpoint}/dual_coords.nc",
        shadow_time="results/{ds}/viewpoints/{viewpoint}/shadow_time.nc",
        reference=get_reference,
    output:
        nc="results/{ds}/viewpoints/{viewpoint}/dual_view.nc",
        exr="results/{ds}/viewpoints/{viewpoint}/dual_view.exr",
        png="results/{ds}/viewpoints/{viewpoint}/dual_view.png",
    log:
        "logs/{ds}/viewpoint_{viewpoint}_dual_view.log",
    benchmark:
        "benchmarks/{ds}/viewpoint_{viewpoint}_dual_view.tsv"
