# Stage: per-pixel shadow time of every sweep the dataset needs, in one dataset.


rule shadow_time:
    input:
        frames=get_frames,
    output:
        "results/{ds}/shadow_time.nc",
    params:
        sweeps=get_sweeps,
        method=config["shadow_time"]["method"],
        options=as_json(config["shadow_time"]["params"]),
    resources:
        mem_mb=get_shadow_time_mem_mb,
        runtime=get_shadow_time_runtime,
    log:
        "logs/{ds}/shadow_time.log",
    benchmark:
        "benchmarks/{ds}/shadow_time.tsv"
    conda:
        "../envs/shadowcam.yaml"
    shell:
        "shadowcam shadow-time --frames {input.frames} --sweeps {params.sweeps}"
        " --method {params.method} --params {params.options:q} --out {output} > {log} 2>&1"
