"""Scenes: a modeller's own 1-D problem as config `scenes` (`scene`: its source, flow, reaction,
target and candidate models; `checks`: the rules between a scene's parts), its reference where it
reacts (`reference`: a closed form, or A + B -> C solved by numerics/reaction_diffusion), and whether
its target can be judged at all (`defined`). Imports from `core`, `numerics` and `models`."""
