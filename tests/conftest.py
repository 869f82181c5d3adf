"""Shared fixtures; MPI-safe (collect garbage and synchronise after each test)."""

import gc

import pytest

from mpi4py import MPI

import fenics_contact  # noqa: F401  (loads the DOLFINx wheel before dolfinx)


@pytest.fixture(autouse=True)
def _mpi_sync():
    yield
    gc.collect()
    MPI.COMM_WORLD.Barrier()
