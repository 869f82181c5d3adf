"""The node lookup installed in FFCx's value numbering gives FFCx's own answers."""

import ufl
from ffcx.ir.analysis import valuenumbering

import fenics_contact  # noqa: F401  (installs the lookup)
from fenics_contact import form_compiler


def test_installed_on_import():
    assert valuenumbering.ValueNumberer.get_node_symbols is form_compiler._node_symbols


def test_lookup_returns_the_scan_answers(monkeypatch, tmp_path):
    """Every lookup of compiling a hyperelastic residual (an empty cache), both ways."""
    import numpy as np
    from dolfinx import fem, mesh

    from mpi4py import MPI

    domain = mesh.create_unit_square(MPI.COMM_SELF, 2, 2)
    V = fem.functionspace(domain, ("Lagrange", 1, (2,)))
    u, v = fem.Function(V), ufl.TestFunction(V)
    F = ufl.Identity(2) + ufl.grad(u)
    psi = ufl.tr(F.T * F) ** 2 + ufl.conditional(ufl.lt(u[0], u[1]), ufl.det(F), ufl.tr(F)) ** 2
    residual = ufl.derivative(psi * ufl.dx, u, v)

    scan = form_compiler._original["get_node_symbols"]
    calls = []

    def both(self, expr):
        mine = form_compiler._node_symbols(self, expr)
        assert mine == scan(self, expr)
        calls.append(expr)
        return mine

    monkeypatch.setattr(valuenumbering.ValueNumberer, "get_node_symbols", both)
    compiled = fem.form([residual, ufl.derivative(residual, u)],
                        jit_options={"cache_dir": str(tmp_path)})
    assert len(calls) > 20
    u.interpolate(lambda x: np.vstack([0.1 * x[1], -0.05 * x[0]]))
    assert np.isfinite(fem.assemble_vector(compiled[0]).array).all()


def test_uninstall_and_install_again():
    form_compiler.uninstall()
    assert valuenumbering.ValueNumberer.get_node_symbols is not form_compiler._node_symbols
    assert form_compiler.install()
    assert valuenumbering.ValueNumberer.get_node_symbols is form_compiler._node_symbols


def test_generated_code_is_the_same_with_and_without_the_shims(tmp_path):
    """The dispatch and cell shims change no character of the generated C."""
    import basix.ufl
    import ffcx
    import ffcx.codegeneration.jit
    from dolfinx import default_scalar_type, fem, mesh
    from ufl.corealg.dag_traverser import DAGTraverser

    from mpi4py import MPI

    domain = mesh.create_unit_cube(MPI.COMM_SELF, 1, 1, 1)
    V = fem.functionspace(domain, ("Lagrange", 1, (3,)))
    u, v = fem.Function(V), ufl.TestFunction(V)
    F = ufl.variable(ufl.Identity(3) + ufl.grad(u))
    psi = ufl.tr(F.T * F) - 3 - 2 * ufl.ln(ufl.det(F)) + ufl.ln(ufl.det(F)) ** 2
    n = ufl.FacetNormal(domain)
    residual = (ufl.inner(ufl.diff(psi, F), ufl.grad(v)) * ufl.dx
                + ufl.conditional(ufl.lt(u[2], 0.1), u[2], 0.0) * ufl.dot(n, v) * ufl.ds)
    forms = [residual, ufl.derivative(residual, u)]
    options = ffcx.get_options({"scalar_type": default_scalar_type})

    def generated(cache: str) -> str:
        _, _, code = ffcx.codegeneration.jit.compile_forms(
            forms, options=options, cache_dir=str(tmp_path / cache),
            cffi_extra_compile_args=["-O0"])
        return "".join(code)

    element = V.ufl_element()
    assert element.cell is element.cell  # one cell per name
    assert type(DAGTraverser.__dict__["process"]) is form_compiler._Dispatch
    shimmed = generated("shimmed")
    form_compiler.uninstall()
    try:
        assert element.cell is not element.cell
        plain = generated("plain")
    finally:
        assert form_compiler.install()
    assert isinstance(basix.ufl._ElementBase.__dict__["cell"], property)
    assert shimmed == plain
    assert "tabulate_tensor" in shimmed
