"""The bushing models and their FMI face (see README.md).

``__version__`` is the project's version, in one place: pyproject.toml reads it, both command
line tools print it (``--version``) and every FMU carries it in its modelDescription.
"""
__version__ = "0.2.0"
