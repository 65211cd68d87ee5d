# The adaptive searches' input functions: thin wrappers over the search engine
# (analysis/search.py), which owns the rounds and what each round reads. A search kind names its
# searches (search_of), its round checkpoint and the run table of each plan row; its rules are in
# optimum.smk and scenes.smk.


def optimum_settings(wildcards):
    """What a search needs besides its own section: case_defaults, t_final, time steps (Search.from_config)."""
    return {
        "case_defaults": config.get("case_defaults", {}),
        "physics": {"t_final": config["physics"]["t_final"]},
        "time": config.get("time", {}),
    }


def optimum_kind(name):
    """The optimum search ``name`` (built and checked: crosschecks.check_search) and the run
    tables of a plan's seed blocks."""
    if name not in OPTIMUM:
        raise WorkflowError(f"no optimum search {name!r} in config optimum: one of {', '.join(OPTIMUM)}")
    search = OPTIMUM[name]

    def plan_paths(plan):
        return [run_path(search.case_at(getattr(r, search.over)), int(r.first), int(r.last)) for r in plan.itertuples()]

    return search, plan_paths


def scene_kind(name):
    """The scene ``name``'s search (the scene built and checked) and the run tables of a plan's rows."""
    from particle_entropy.analysis.scene_search import SceneSearch  # here: parsing imports no pandas

    if name not in SCENES:
        raise WorkflowError(f"no scene {name!r} in config scenes: one of {', '.join(SCENES) or 'none'}")
    search = SceneSearch(SCENES[name])
    return search, search.plan_paths


def search_inputs(search_of, checkpoint, final=False):
    """The input function of a kind's round checkpoint (round k: plan k-1 and its runs) or, ``final``,
    of its table (the finished plan and its runs): AdaptiveSearch.round_inputs / final_inputs."""

    def inputs(wildcards):
        search, plan_paths = search_of(wildcards.name)  # built and checked before its first job

        def plan_at(k):
            return getattr(checkpoints, checkpoint).get(name=wildcards.name, k=str(k)).output[0]

        if final:
            return search.final_inputs(plan_at, plan_paths)
        return search.round_inputs(int(wildcards.k), plan_at, plan_paths)

    return inputs


optimum_round_inputs = search_inputs(optimum_kind, "optimum_round")
optimum_final_inputs = search_inputs(optimum_kind, "optimum_round", final=True)
_scene_round_inputs = search_inputs(scene_kind, "scene_round")


def scene_round_inputs(wildcards):
    """A scene's round reads its last plan and runs, and a reactive scene's its reference too (a target
    the reference cannot judge stops the search before any run: scenes/defined.py)."""
    out = _scene_round_inputs(wildcards)
    scene = SCENES[wildcards.name]
    if scene.reaction is not None:
        return {**out, "reference": reactive_reference_path(scene)}
    return out


scene_final_inputs = search_inputs(scene_kind, "scene_round", final=True)


def scene_table_inputs(wildcards):
    """A scene's table reads its finished plan and runs, and a reactive scene its reference too."""
    out = scene_final_inputs(wildcards)
    scene = SCENES[wildcards.name]
    if scene.reaction is not None:
        return {**out, "reference": reactive_reference_path(scene)}
    return out
