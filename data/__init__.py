"""The project's parameter sets and synthetic measurements.

Installed as the package ``bushing_data`` (pyproject.toml), so that ``bushing-build-fmu`` finds
the default parameter sets outside the checkout.
"""
