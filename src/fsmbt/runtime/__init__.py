"""Run converted models with the user's own code: the Python runtime of LEBTs (python_runtime)."""
