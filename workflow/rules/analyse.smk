rule metrics:
    input:
        "results/cases/{case}/run.nc",
    output:
        "results/cases/{case}/metrics.nc",
    params:
        settings=lambda wc: yaml.safe_dump({k: config.get(k) for k in METRIC_KEYS}),
        code=METRICS_HASH,
        config=CONFIG_FILE,
    log:
        "results/logs/metrics_{case}.log",
    shell:
        "python -m study metrics {params.config} {input} -o {output} 2> {log}"


rule campaign:
    input:
        runs=expand("results/cases/{case}/run.nc", case=CASE_IDS),
        metrics=expand("results/cases/{case}/metrics.nc", case=CASE_IDS),
    output:
        "results/campaign.nc",
    params:
        config=CONFIG_FILE,
    log:
        "results/logs/campaign.log",
    shell:
        "python -m study reduce {params.config} --results results/cases -o {output} 2> {log}"
