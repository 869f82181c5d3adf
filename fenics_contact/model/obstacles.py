"""Rigid obstacles and their signed gap in the current configuration.

The gap ``g(x)`` is positive where the body is clear of the obstacle and
negative where it penetrates, with ``x = X + u`` the current position. Each
obstacle's position lives in ``dolfinx.fem.Constant`` objects, so moving it
between load steps changes values, not compiled code.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import ufl
from dolfinx import fem, mesh


class RigidObstacle:
    """Base class: a rigid body whose placement can move rigidly."""

    def __init__(self, domain: mesh.Mesh, reference_point: Sequence[float]) -> None:
        gdim = domain.geometry.dim
        point = np.asarray(reference_point, dtype=float)
        if point.shape != (gdim,):
            raise ValueError(
                f"Obstacle point {list(point)} has {point.size} coordinates; "
                f"the mesh is {gdim}D: give {gdim}."
            )
        self._home = point
        self.point = fem.Constant(domain, point.copy())

    def translate_to(self, offset: Sequence[float]) -> None:
        """Place the obstacle at its initial position plus ``offset`` (length units)."""
        self.point.value[:] = self._home + np.asarray(offset, dtype=float)

    def gap(self, x: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
        """Signed normal gap at the current position ``x`` (length units)."""
        raise NotImplementedError

    def gap_value(self, x: np.ndarray) -> np.ndarray:
        """The same gap evaluated with numpy on points of shape (n, gdim)."""
        raise NotImplementedError

    def normal_at(self, x: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
        """Unit normal at ``x`` pointing to the body's side (the gradient of the gap)."""
        raise NotImplementedError

    def normal_value(self, x: np.ndarray) -> np.ndarray:
        """The same normal evaluated with numpy on points of shape (n, gdim)."""
        raise NotImplementedError


class RigidPlane(RigidObstacle):
    """Half-space below a plane through ``point`` with outward ``normal``.

    The body must stay on the side the normal points to: g = (x - x0) . n.
    ``normal`` need not be of unit length: it is normalised (length units for
    ``point``).
    """

    def __init__(
        self, domain: mesh.Mesh, point: Sequence[float], normal: Sequence[float]
    ) -> None:
        super().__init__(domain, point)
        n = np.asarray(normal, dtype=float)
        if n.shape != self._home.shape or not np.linalg.norm(n) > 0:
            raise ValueError(f"Plane normal {list(n)} must be a nonzero {n.size}-vector.")
        self.normal = fem.Constant(domain, n / np.linalg.norm(n))

    def gap(self, x: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
        """G = (x - x0) . n."""
        return ufl.dot(x - self.point, self.normal)

    def gap_value(self, x: np.ndarray) -> np.ndarray:
        """Numpy gap."""
        return (x - self.point.value) @ self.normal.value

    def normal_at(self, x: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
        """The plane's unit normal n (the same at every x)."""
        return self.normal

    def normal_value(self, x: np.ndarray) -> np.ndarray:
        """Numpy normal: n at every point."""
        return np.broadcast_to(self.normal.value, np.shape(x)).copy()


class RigidBall(RigidObstacle):
    """A rigid circle (2D) or sphere (3D) of given radius.

    ``centre`` (length, one entry per coordinate) and ``radius`` (length) place
    it in the reference frame; a motion moves the centre. ``inside=False``
    (default) keeps the body outside the ball: g = |x - c| - R. ``inside=True``
    keeps it inside a cradle: g = R - |x - c|.
    """

    def __init__(
        self,
        domain: mesh.Mesh,
        centre: Sequence[float],
        radius: float,
        inside: bool = False,
    ) -> None:
        super().__init__(domain, centre)
        if not radius > 0:
            raise ValueError(f"Obstacle radius must be > 0, got {radius}.")
        self.radius = fem.Constant(domain, float(radius))
        self.inside = inside

    def gap(self, x: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
        """G = +-(|x - c| - R)."""
        distance = ufl.sqrt(ufl.dot(x - self.point, x - self.point))
        g = distance - self.radius
        return -g if self.inside else g

    def gap_value(self, x: np.ndarray) -> np.ndarray:
        """Numpy gap."""
        g = np.linalg.norm(x - self.point.value, axis=1) - float(self.radius.value)
        return -g if self.inside else g

    def normal_at(self, x: ufl.core.expr.Expr) -> ufl.core.expr.Expr:
        """Radial unit normal +-(x - c)/|x - c| (minus for a cradle)."""
        d = x - self.point
        n = d / ufl.sqrt(ufl.dot(d, d))
        return -n if self.inside else n

    def normal_value(self, x: np.ndarray) -> np.ndarray:
        """Numpy radial normal (zero at the centre)."""
        d = x - self.point.value
        length = np.linalg.norm(d, axis=1, keepdims=True)
        n = np.divide(d, length, out=np.zeros_like(d), where=length > 0)
        return -n if self.inside else n
