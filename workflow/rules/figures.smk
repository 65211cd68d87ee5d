# One rule per figure: tables in; figures/<fig>.png and .pdf and the plotted data
# (results/figures/<fig>.parquet) out. Restyling reruns no simulation.

for _fig in PLOTTED:

    rule:
        name:
            f"plot_{_fig}"
        input:
            INPUTS.section_inputs(_fig),
        output:
            png=report(
                f"figures/{_fig}.png",
                caption=f"../report/{_fig}.rst",
                category=FIGURE[_fig].category,
                labels=figure_labels(_fig, f"plot_{_fig}", FIGURE_DATA_PATTERN.format(fig=_fig)),
            ),
            pdf=f"figures/{_fig}.pdf",
            data=FIGURE_DATA_PATTERN.format(fig=_fig),
        log:
            f"logs/plot/{_fig}.log",
        benchmark:
            f"results/benchmarks/plot/{_fig}.tsv"
        localrule: True
        conda:
            "../../envs/particle-entropy.yaml"
        resources:
            mem_mb=1000,
        params:
            fig=_fig,
            cases=INPUTS.section_cases(_fig),
            D=config["physics"]["D"],
            t_final=config["physics"]["t_final"],
            options=figure_options(_fig, config.get("figures", {}).get(_fig, {})),
            code=script_code(SCRIPTS / "plot_figure.py", f"figures.{_fig}"),  # the script draws figures.<fig>
        script:
            "../scripts/plot_figure.py"
