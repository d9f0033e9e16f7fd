# Stage: render a synthetic capture (datasets whose manifest has a `synthetic:` block).
# Writes frames, capture.json (the capture description) and ground_truth.nc.


rule render:
    input:
        "data_manifest/{ds}.yaml",
    output:
        directory("results/{ds}/capture"),
    log:
        "logs/{ds}/render.log",
    benchmark:
        "benchmarks/{ds}/render.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_render_mem_mb,
        runtime=30,
    shell:
        "shadowcam render --manifest {input} --out {output} > {log} 2>&1"
