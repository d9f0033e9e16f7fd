# Stage: accuracy against ground truth (only datasets that have it: synthetic ones,
# or user data with a `ground_truth:` entry).


rule accuracy:
    input:
        capture=get_capture_input,
        shadow_time="results/{ds}/shadow_time.nc",
        stages=get_accuracy_stages,
        reference=get_accuracy_reference,
        viewpoints=get_viewpoint_products,
    output:
        json="results/{ds}/accuracy.json",
        # shown in the report as the figure "accuracy" (HTML); a CSV there only downloads
        csv="results/{ds}/accuracy.csv",
    log:
        "logs/{ds}/accuracy.log",
    benchmark:
        "benchmarks/{ds}/accuracy.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_image_mem_mb,
        runtime=15,
    params:
        manifest=get_capture_manifest,
        stages=get_accuracy_flags,
        viewpoints=get_viewpoint_flags,
    shell:
        "shadowcam accuracy --manifest {params.manifest} --shadow-time {input.shadow_time}"
        " {params.stages} {params.viewpoints}"
        " --out-json {output.json} --out-csv {output.csv} > {log} 2>&1"
