# Stage: the shadow pushbroom of a single-sweep lab capture (shadow time x position along
# the shadow line), planned instead of the dual stages when the capture has one scene sweep.


rule lab_pushbroom:
    input:
        shadow_time="results/{ds}/shadow_time.nc",
        reference=get_reference,
    output:
        nc="results/{ds}/pushbroom.nc",
        png="results/{ds}/pushbroom.png",
    log:
        "logs/{ds}/lab_pushbroom.log",
    benchmark:
        "benchmarks/{ds}/lab_pushbroom.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_image_mem_mb,
        runtime=15,
    params:
        reference=get_flag("--reference", "reference"),
    shell:
        "shadowcam lab-pushbroom --shadow-time {input.shadow_time} {params.reference}"
        " --out {output.nc} --png {output.png} > {log} 2>&1"
