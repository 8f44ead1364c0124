"""The experiment layer: YAML configs -> algorithms x cases x runs -> records -> reports."""
from .config import ExperimentConfig, load_config
from .runner import ExperimentResult, run_experiment

__all__ = ["ExperimentConfig", "ExperimentResult", "load_config", "run_experiment"]
