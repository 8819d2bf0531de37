"""Shared helpers of tmclsim's Python tests. The ``tmcl_module`` fixture
comes from the package's pytest plugin (entry point), like for users."""

import pytest


@pytest.fixture
def module():
    """A fresh in-process TMCM-1141 on the built-in stage."""
    import tmclsim

    return tmclsim.Module()
