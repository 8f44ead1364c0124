"""Example fkopt plug-ins (see README.md beside pyproject.toml)."""
