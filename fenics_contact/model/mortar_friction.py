"""The weighted incremental slip of a mortar striker node, in UFL (2D).

Coulomb friction on a mortar pair (:mod:`.mortar`) uses the tangential
multiplier lam_t (P1 on the striker's contact submesh, as for
node-to-segment pairs) and, at striker node j, the weighted slip

    s~_j = T_j^T int_{segments} N_j [(u_s - u_s_prev) - (u_t - u_t_prev)] dA / A~_j

on the same segments, Gauss points and weights as the weighted gap: u_s is
the displacement of the striker point (linear on the striker facet), u_t
that of the target point the ray x_s + alpha n_s hits (linear on the
target facet, at its current local coordinate), both at the current
segment geometry, so the reference positions cancel and a common rigid
translation gives s~_j = 0 with zero derivative. T_j = (n_y, -n_x) of
n = -(m_L n_L + m_R n_R)/|...|, the average of the node's two striker
facet normals turned towards the target (the node-to-segment pairs use the
target's normal). A node whose support meets no target facet takes its
own increment T_j^T (u - u_prev) (it is open: its Coulomb radius is 0).
The Alart-Curnier projection on the nodal pairs (lam_t_j, s~_j) with the
radius mu |p_n_j| is :class:`~.friction_terms.CoulombFriction`'s.
"""

from __future__ import annotations

import ufl
from dolfinx import fem

from fenics_contact.model.friction import tangent_basis


def mortar_slip(transfer, X_j: ufl.core.expr.Expr, u: fem.Function, u_prev: fem.Function,
                w_prev: fem.Function) -> tuple[ufl.core.expr.Expr, ufl.core.expr.Expr]:
    """(T_j, s~_j) of a :class:`~.mortar.MortarTransfer` at the striker node ``X_j``.

    ``w_prev``: the previous displacements of the node's stencil rows (data).
    """
    row = transfer._point
    du_j = u - u_prev

    def du(i: int) -> ufl.core.expr.Expr:
        return row(transfer.w, i) - row(w_prev, i)

    x_j = X_j + u
    points, full = transfer.segments(X_j, x_j)
    normals = {}
    vec, area = ufl.zero(2), 0
    for weight, (x1, x2, s, n_s), (k, a, b), xi, alpha in points:
        normals[s] = n_s
        du_s = ((1.0 - xi) * du(0) + xi * du_j if s == 0
                else (1.0 - xi) * du_j + xi * du(1))
        p = x1 + xi * (x2 - x1) + alpha * n_s
        e = b - a
        m_k = transfer.m[2 + k]  # an unused slot has a = b: keep 0/0 out
        eta = ufl.dot(p - a, e) / (ufl.dot(e, e) + (1.0 - m_k))
        du_t = (1.0 - eta) * du(2 + 2 * k) + eta * du(3 + 2 * k)
        vec = vec + weight * (du_s - du_t)
        area = area + weight
    n = -(transfer.m[0] * normals[0] + transfer.m[1] * normals[1])
    n = n / ufl.sqrt(ufl.dot(n, n))
    T = tangent_basis(n, 2)
    floor = 1e-8 * full
    weighted = (T.T * vec)[0] / ufl.max_value(area, floor)
    own = (T.T * du_j)[0]
    return T, ufl.as_vector([ufl.conditional(ufl.gt(area, floor), weighted, own)])


__all__ = ["mortar_slip"]
