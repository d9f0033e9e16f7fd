# Stage: light-field captures (manifest kind lightfield, paper VI, Fig. 17): render the
# capture (synthetic) or describe it from the manifest (captured), merge each sweep's
# exposure brackets to HDR, the wire's shadow times per screen and sweep, the rays, renders at config lightfield.render_positions_m,
# the IES / EULUMDAT candela files, the ground truth once (rendered captures), accuracy
# and the report figures.
# Outputs live under results/{ds}/lightfield/; input functions in lightfield_inputs.smk.


rule render_lightfield:
    input:
        get_lightfield_sources,
    output:
        directory("results/{ds}/lightfield/capture"),
    log:
        "logs/{ds}/render_lightfield.log",
    benchmark:
        "benchmarks/{ds}/render_lightfield.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_lightfield_mem_mb,
        runtime=30,
    params:
        manifest="data_manifest/{ds}.yaml",
    shell:
        "shadowcam render-lightfield --manifest {params.manifest} --out {output} > {log} 2>&1"


rule lightfield_hdr:
    input:
        get_lightfield_capture,
    output:
        "results/{ds}/lightfield/hdr/{sweep}.npy",
    log:
        "logs/{ds}/lightfield_hdr_{sweep}.log",
    benchmark:
        "benchmarks/{ds}/lightfield_hdr_{sweep}.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_lightfield_mem_mb,
        runtime=30,
    shell:
        "shadowcam lightfield-hdr --capture {input} --sweep {wildcards.sweep}"
        " --out {output} > {log} 2>&1"


rule lightfield_shadow_times:
    input:
        hdr="results/{ds}/lightfield/hdr/{sweep}.npy",
        capture=get_lightfield_capture,
    output:
        "results/{ds}/lightfield/shadow_times/{sweep}.nc",
    log:
        "logs/{ds}/lightfield_shadow_times_{sweep}.log",
    benchmark:
        "benchmarks/{ds}/lightfield_shadow_times_{sweep}.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_lightfield_mem_mb,
        runtime=30,
    shell:
        "shadowcam lightfield-shadow-times --hdr {input.hdr} --capture {input.capture}"
        " --out {output} > {log} 2>&1"


rule lightfield_rays:
    input:
        capture=get_lightfield_capture,
        sweeps=get_lightfield_sweeps,
    output:
        "results/{ds}/lightfield/rays.nc",
    log:
        "logs/{ds}/lightfield_rays.log",
    benchmark:
        "benchmarks/{ds}/lightfield_rays.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_lightfield_mem_mb,
        runtime=15,
    params:
        anchor=config["lightfield"]["ray_anchor"],
    shell:
        "shadowcam lightfield-rays --capture {input.capture} --sweeps {input.sweeps}"
        " --anchor {params.anchor} --out {output} > {log} 2>&1"


rule lightfield_render:
    input:
        rays="results/{ds}/lightfield/rays.nc",
        capture=get_lightfield_capture,
    output:
        "results/{ds}/lightfield/renders.nc",
    log:
        "logs/{ds}/lightfield_render.log",
    benchmark:
        "benchmarks/{ds}/lightfield_render.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_lightfield_mem_mb,
        runtime=15,
    params:
        positions=" ".join(str(p) for p in config["lightfield"]["render_positions_m"]),
        pitch_factor=config["lightfield"]["pitch_factor"],
    shell:
        "shadowcam lightfield-render --rays {input.rays} --capture {input.capture}"
        " --positions-m {params.positions} --pitch-factor {params.pitch_factor}"
        " --out {output} > {log} 2>&1"


rule lightfield_export:
    input:
        "results/{ds}/lightfield/rays.nc",
    output:
        ies="results/{ds}/lightfield/source.ies",
        ldt="results/{ds}/lightfield/source.ldt",
        table="results/{ds}/lightfield/far_field.nc",
    log:
        "logs/{ds}/lightfield_export.log",
    benchmark:
        "benchmarks/{ds}/lightfield_export.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_lightfield_export_mem_mb,
        runtime=15,
    params:
        c_step=config["lightfield"]["c_step_deg"],
        gamma_step=config["lightfield"]["gamma_step_deg"],
    shell:
        "shadowcam lightfield-export --rays {input} --c-step-deg {params.c_step}"
        " --gamma-step-deg {params.gamma_step} --ies {output.ies} --ldt {output.ldt}"
        " --table {output.table} > {log} 2>&1"


rule lightfield_truth:
    input:
        manifest="data_manifest/{ds}.yaml",
        rays="results/{ds}/lightfield/rays.nc",
        renders="results/{ds}/lightfield/renders.nc",
    output:
        "results/{ds}/lightfield/truth.nc",
    log:
        "logs/{ds}/lightfield_truth.log",
    benchmark:
        "benchmarks/{ds}/lightfield_truth.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_lightfield_export_mem_mb,
        runtime=15,
    shell:
        "shadowcam lightfield-truth --manifest {input.manifest} --rays {input.rays}"
        " --renders {input.renders} --out {output} > {log} 2>&1"


rule lightfield_accuracy:
    input:
        capture=get_lightfield_capture,
        sweeps=get_lightfield_sweeps,
        rays="results/{ds}/lightfield/rays.nc",
        renders="results/{ds}/lightfield/renders.nc",
        truth="results/{ds}/lightfield/truth.nc",
    output:
        json="results/{ds}/lightfield/accuracy.json",
        csv="results/{ds}/lightfield/accuracy.csv",
    log:
        "logs/{ds}/lightfield_accuracy.log",
    benchmark:
        "benchmarks/{ds}/lightfield_accuracy.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_lightfield_export_mem_mb,
        runtime=15,
    shell:
        "shadowcam lightfield-accuracy --capture {input.capture} --sweeps {input.sweeps}"
        " --rays {input.rays} --renders {input.renders} --truth {input.truth}"
        " --json {output.json} --csv {output.csv} > {log} 2>&1"


rule lightfield_report:
    input:
        hdr=get_lightfield_hdr,
        sweeps=get_lightfield_sweeps,
        renders="results/{ds}/lightfield/renders.nc",
        table="results/{ds}/lightfield/far_field.nc",
        truth=get_lightfield_truth,
    output:
        report(
            directory("results/{ds}/lightfield/figures"),
            patterns=["{figure}.png"],
            caption="../report/lightfield.rst",
            category="{ds}",
            subcategory="light field",
        ),
    log:
        "logs/{ds}/lightfield_report.log",
    benchmark:
        "benchmarks/{ds}/lightfield_report.tsv"
    conda:
        "../envs/shadowcam.yaml"
    resources:
        mem_mb=get_lightfield_export_mem_mb,
        runtime=15,
    params:
        truth=lambda wildcards, input: f"--truth {input.truth}" if input.truth else "",
    shell:
        "shadowcam lightfield-report --hdr {input.hdr} --sweeps {input.sweeps}"
        " --renders {input.renders} --table {input.table} {params.truth}"
        " --outdir {output} > {log} 2>&1"
