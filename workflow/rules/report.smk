FIGURES = ["fig02_zeta_f", "fig03_zeta_h", "fig04_zeta_fs", "fig05_velocity_profiles",
           "fig06_zeta_u", "fig07_front_particles", "fig08_shifting_zeta_u",
           "fig09_shifting_zeta_f", "fig10_shifting_zeta_h", "fig11_cost_vs_error",
           "fig12_stability_map"]
FMT = config["figures"]["format"]


rule figures:
    input:
        "results/campaign.nc",
    output:
        [report(f"results/figures/{f}.{FMT}", caption=f"../report/{f}.rst", category="Figures")
         for f in FIGURES],
    params:
        settings=lambda wc: yaml.safe_dump(config["figures"]),
        config=CONFIG_FILE,
    shell:
        "python -m study figures {params.config} {input} -o results/figures"


rule report_html:
    input:
        campaign="results/campaign.nc",
        figures=expand("results/figures/{f}.{fmt}", f=FIGURES, fmt=FMT),
    output:
        "reports/report.html",
    params:
        config=CONFIG_FILE,
    shell:
        "python -m study report {params.config} {input.campaign} --figures results/figures -o {output}"
