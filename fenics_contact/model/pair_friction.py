"""Coulomb friction between two deformable bodies (node-to-segment).

The frictional terms of :class:`~fenics_contact.model.friction.FrictionMixin`
on the node-to-segment pair of :mod:`.pairs`. The tangent frame is that of
the assigned target facet, T = tangent_basis(n) with n its unit outward
normal (2D: T = -t/|t|, t = x_b - x_a). The slip increment over the load
step is the relative displacement increment of the contacting material
points,

    dg_t = T^T [(x_s - x_s_prev) - (x_p - x_p_prev)],
    x_p = sum_k N_k(xi) x_k,   x_p_prev = sum_k N_k(xi) x_k_prev,

with x_s the striker node, N_k(xi) the weights of the current projection
point on the facet (2D: 1 - xi and xi with xi = (x_s - x_a) . t / |t|^2;
3D: the barycentric coordinates) and x_k_prev the facet's vertices at the
last converged step: the same material point of the target (same xi) then
and now. The reference positions cancel, so

    dg_t = T^T [(u - u_prev) - sum_k N_k (w_k - w_k_prev)],

where w_k_prev, the previous displacements of the assigned vertices, are
P1 data on the striker's submesh filled by the search from u_prev (not
unknowns). A striker node that changes facet is measured against its new
facet's vertices at the last step. Under a common rigid translation of both
bodies dg_t = 0 and its derivative vanishes, so the friction forces on the
striker and on the target balance exactly.

Friction has no potential: every residual (u and each w_k) gains the
tangential work tau . d(dg_t)[.] and the Newton Jacobian is the derivative
of the residuals (the condensing kernel differentiates the residual blocks,
not an energy). Signs as in :mod:`.friction`: the striker receives -T tau.
"""

from __future__ import annotations

import ufl
from dolfinx import fem

from fenics_contact.model.friction import FrictionMixin, tangent_basis
from fenics_contact.model.pairs import TwoBodyProblem


class FrictionalTwoBodyProblem(FrictionMixin, TwoBodyProblem):
    """Two deformable bodies with Coulomb friction of coefficient ``mu``.

    Arguments as :class:`TwoBodyProblem` plus ``mu`` and ``tangential_r_max``
    (r_t = min(r, tangential_r_max E/L), E the pair modulus, L the extent of
    the striker's contact surface; None: r_t = r).
    :meth:`commit` moves u_prev and the target's previous displacements
    forward; the stepping calls it before each increment.
    """

    def _slip_increment(self) -> tuple[ufl.core.expr.Expr, ufl.core.expr.Expr]:
        """T of the target facet and the relative slip of the contacting points."""
        pair = self.pair
        self.w_prev = pair.track_previous(self.u_prev)
        x_s = ufl.SpatialCoordinate(self.domain) + self.u
        tangents = tangent_basis(pair.normal(), self.gdim)
        target = sum(
            (N * (wk - wk_prev)
             for N, wk, wk_prev in zip(pair.shape_weights(x_s), pair.w, self.w_prev,
                                       strict=True)),
            ufl.zero(self.gdim),
        )
        return tangents, tangents.T * ((self.u - self.u_prev) - target)

    def _commit_frame(self) -> None:
        """w_k_prev <- the assigned vertices' displacements in the new u_prev."""
        self.pair.set_previous()

    def _contact_residual(self, wk: fem.Function, q: ufl.Argument) -> ufl.Form:
        """Normal plus tangential contact residual for w_k (see :meth:`target_force`)."""
        return super()._contact_residual(wk, q) + self._friction_work(self.traction_t)(wk, q)
