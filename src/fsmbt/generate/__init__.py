"""Seeded, reproducible random FSMs and BTs for tests, benchmarks and ``fsmbt generate``."""

from fsmbt.generate.dataset import DatasetSpec, generate_models, model_seed
from fsmbt.generate.generator import make_rng, random_bt, random_fsm
from fsmbt.generate.vocab import SCENARIOS, Vocabulary, vocabulary

__all__ = [
    "random_fsm",
    "random_bt",
    "make_rng",
    "SCENARIOS",
    "Vocabulary",
    "vocabulary",
    "DatasetSpec",
    "generate_models",
    "model_seed",
]
