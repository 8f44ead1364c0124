"""Experiment files (no `kind:` key): YAML configs -> algorithms x cases x runs -> records -> reports."""
from fkopt.kinds.experiment.config import ExperimentConfig, load_config
from fkopt.kinds.experiment.runner import run_experiment

__all__ = ["ExperimentConfig", "load_config", "run_experiment"]
