# One rule per figure: tables in, figures/figNN.png and .pdf out. Restyling reruns no simulation.

for _fig in ALL_FIGURES:

    rule:
        name:
            f"plot_{_fig}"
        input:
            figure_inputs(_fig),
        output:
            png=report(f"figures/{_fig}.png", caption=f"../report/{_fig}.rst", category="Figures"),
            pdf=f"figures/{_fig}.pdf",
        log:
            f"logs/plot/{_fig}.log",
        params:
            fig=_fig,
            D=config["physics"]["D"],
            t_final=config["physics"]["t_final"],
        resources:
            mem_mb=1000,
        conda:
            "../../envs/particle-entropy.yaml"
        script:
            "../scripts/plot_figure.py"
