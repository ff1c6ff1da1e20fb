"""Shared test support: model builders, generators and a scripted LLM server used by several
test folders. Importable as ``support.<module>`` because pyproject.toml's pytest section puts
``tests/`` on ``pythonpath``; it is not part of the fsmbt package and never ships with it.

- ``conv_helpers``, ``conv_hfsm_gen``: conversion checks and random hierarchical FSMs.
- ``base_helpers``: the baselines' shared checks.
- ``ver_models``, ``mutation_families``: verifier models and the mutation families (shared by
  tests/verify and tests/verify/nusmv).
- ``random_trees``: seeded random behavior trees (and a hypothesis strategy) for the semantics
  tests.
- ``scripted_server``: a local OpenAI-compatible server replaying scripted answers.
- ``sim_helpers``: the simulation tests' models, mutants and divergence checks (tests/sim).
"""
