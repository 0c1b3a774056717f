rule metrics:
    input:
        f"{R}/cases/{{case}}/run.nc",
    output:
        f"{R}/cases/{{case}}/metrics.nc",
    params:
        settings=lambda wc: yaml.safe_dump({k: config.get(k) for k in METRIC_KEYS}),
        code=METRICS_HASH,
        config=CONFIG_FILE,
    log:
        f"{R}/logs/metrics_{{case}}.log",
    shell:
        f"{PY} -m study metrics {{params.config}} {{input}} -o {{output}} 2> {{log}}"


rule campaign:
    input:
        runs=expand(f"{R}/cases/{{case}}/run.nc", case=CASE_IDS),
        metrics=expand(f"{R}/cases/{{case}}/metrics.nc", case=CASE_IDS),
    output:
        f"{R}/campaign.nc",
    params:
        config=CONFIG_FILE,
    log:
        f"{R}/logs/campaign.log",
    shell:
        f"{PY} -m study reduce {{params.config}} --results {R}/cases -o {{output}} 2> {{log}}"
