"""Which rigid motions of a body its Dirichlet conditions leave free.

A rigid motion u(x) = a + w x (x - c) (2D: one rotation about z) is held when
some prescribed component at some constrained node does not vanish for it.
Collect, for every prescribed component i and every node p of its facets,
the row of the rigid-mode basis evaluated at p in component i; the motions
left free are the null space of that matrix. Contact and penalty terms do not
count: before contact is made they hold nothing, and a singular stiffness is
what a Newton solve then meets.

The check works on the Gram matrix M^T M (at most 6 x 6), summed over the
MPI ranks, with coordinates centred on the body's bounding box and scaled by
its size so that translations and rotations weigh alike.

:class:`AssemblyModes` does the same for every body of a mesh at once and
adds the contacts: the gaps closed at the start (before the run, unilateral)
or the contact nodes closed in a deformed state (every converged iterate,
both ways; :mod:`.holding` hands it a problem's contacts).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from dolfinx import mesh

from mpi4py import MPI

_AXES = "xyz"


def _basis(points: np.ndarray, component: int, gdim: int) -> np.ndarray:
    """Rows: component ``component`` of each rigid mode at ``points`` (n, gdim)."""
    n = points.shape[0]
    if gdim == 2:
        x, y = points[:, 0], points[:, 1]
        modes = [np.full(n, component == 0, float), np.full(n, component == 1, float),
                 -y if component == 0 else x]  # rotation about z: (-y, x)
        return np.column_stack(modes)
    x, y, z = points[:, 0], points[:, 1], points[:, 2]
    # rotations about x: (0, -z, y); about y: (z, 0, -x); about z: (-y, x, 0)
    rot = {
        0: [np.zeros(n), z, -y],
        1: [-z, np.zeros(n), x],
        2: [y, -x, np.zeros(n)],
    }[component]
    trans = [np.full(n, component == k, float) for k in range(3)]
    return np.column_stack(trans + rot)


def _names(gdim: int) -> list[str]:
    if gdim == 2:
        return ["translation in x", "translation in y", "rotation in the x-y plane"]
    return [f"translation in {a}" for a in _AXES] + [f"rotation about the {a} axis" for a in _AXES]


def free_rigid_motions(
    domain: mesh.Mesh,
    conditions: Sequence[tuple[np.ndarray, Sequence[float | None]]],
    cells: np.ndarray | None = None,
) -> list[str]:
    """Names of the rigid motions that the prescribed components leave free.

    Args:
        domain: the body mesh.
        conditions: (local facet indices, value per component with None for a
            free component) of each Dirichlet condition.
        cells: the body's cells in a mesh of several bodies (None: every cell);
            a rotation is named about the centre of their bounding box.

    Returns:
        An empty list when every rigid motion is held, else one phrase per
        free motion (e.g. "translation in x", "rotation about the z axis
        through (0.5, 0)"), collective over the mesh's communicator.
    """
    gdim = domain.geometry.dim
    tdim = domain.topology.dim
    comm = domain.comm
    x = domain.geometry.x[:, :gdim]
    own = x if cells is None else x[np.unique(domain.geometry.dofmaps[0][cells])]
    lo = np.empty(gdim)
    hi = np.empty(gdim)
    comm.Allreduce(own.min(axis=0) if own.size else np.full(gdim, np.inf), lo, op=MPI.MIN)
    comm.Allreduce(own.max(axis=0) if own.size else np.full(gdim, -np.inf), hi, op=MPI.MAX)
    centre = 0.5 * (lo + hi)
    size = float(np.max(hi - lo)) or 1.0
    n_modes = 3 if gdim == 2 else 6
    gram = np.zeros((n_modes, n_modes))
    domain.topology.create_connectivity(tdim - 1, 0)
    for facets, value in conditions:
        facets = np.asarray(facets, dtype=np.int32)
        if facets.size == 0:
            continue
        vertices = np.unique(mesh.entities_to_geometry(domain, tdim - 1, facets).ravel())
        points = (x[vertices] - centre) / size
        for component, v in enumerate(value):
            if v is None:
                continue
            rows = _basis(points, component, gdim)
            gram += rows.T @ rows
    total = np.empty_like(gram)
    comm.Allreduce(gram, total, op=MPI.SUM)
    gram = total
    eigenvalues, vectors = np.linalg.eigh(gram)
    scale = max(float(eigenvalues.max()), 1.0)
    null = vectors[:, eigenvalues <= 1e-10 * scale]
    if null.shape[1] == 0:
        return []
    names = _names(gdim)
    free: list[str] = []
    projector = null @ null.T
    for k in range(n_modes):
        e = np.zeros(n_modes)
        e[k] = 1.0
        if np.linalg.norm(projector @ e) > 1 - 1e-8:
            free.append(names[k] + (f" about ({_fmt(centre)})" if "rotation" in names[k] and
                                    gdim == 2 else ""))
    # motions of the null space not spanned by the pure modes named above
    named = [k for k in range(n_modes) if np.linalg.norm(projector[:, k]) > 1 - 1e-8]
    remaining = null.shape[1] - len(named)
    if remaining > 0:
        rest = null - (np.eye(n_modes)[:, named] @ np.eye(n_modes)[named, :]) @ null
        u, _, _ = np.linalg.svd(rest)
        for j in range(remaining):
            free.append(_describe(u[:, j], centre, size, gdim))
    return free


def _fmt(point: np.ndarray) -> str:
    return ", ".join(f"{c:.4g}" for c in point)


def _describe(mode: np.ndarray, centre: np.ndarray, size: float, gdim: int) -> str:
    """A rigid mode (translation, rotation) in scaled coordinates, in words."""
    if gdim == 2:
        a, w = mode[:2], mode[2]
        if abs(w) < 1e-8:
            return f"translation along ({_fmt(a / np.linalg.norm(a))})"
        # u = a + w (-y, x) vanishes at the point c with a = w (c_y, -c_x)
        c = np.array([-a[1] / w, a[0] / w]) * size + centre
        c = np.where(np.abs(c) < 1e-6 * size, 0.0, c)  # the modes' round-off
        return f"rotation in the x-y plane about ({_fmt(c)})"
    a, w = mode[:3], mode[3:]
    if np.linalg.norm(w) < 1e-8:
        return f"translation along ({_fmt(a / np.linalg.norm(a))})"
    axis = w / np.linalg.norm(w)
    # a = -w x c (+ a screw part along w); c = (w x a) / |w|^2 is the nearest axis point
    c = np.cross(w, a) / np.dot(w, w) * size + centre
    c = np.where(np.abs(c) < 1e-6 * size, 0.0, c)
    return f"rotation about the axis ({_fmt(axis)}) through ({_fmt(c)})"


def assembly_held(
    domain: mesh.Mesh,
    bodies: Sequence[tuple[str, np.ndarray]],
    conditions: Sequence[tuple[np.ndarray, Sequence[float | None]]],
    contact_gaps: Callable[[np.ndarray], np.ndarray],
) -> bool:
    """Whether the Dirichlet conditions and the contacts closed at the start hold every body.

    See :func:`free_assembly_motion`; True when it finds no free motion. Collective.
    """
    return not free_assembly_motion(domain, bodies, conditions, contact_gaps)


def free_assembly_motion(
    domain: mesh.Mesh,
    bodies: Sequence[tuple[str, np.ndarray]],
    conditions: Sequence[tuple[np.ndarray, Sequence[float | None]]],
    contact_gaps: Callable[[np.ndarray], np.ndarray],
    tractions: Sequence[tuple[np.ndarray, Sequence[float]]] = (),
    touching: Callable[[np.ndarray], np.ndarray] | None = None,
) -> list[tuple[str, str]]:
    """A rigid motion of the assembly that nothing holds, body by body ([] when held).

    Each body may move rigidly on its own. A Dirichlet component holds the
    body whose facets carry it both ways. A contact node whose gap is zero
    at the start resists only the motions that close it (the gap is
    unilateral): a free motion is one that the conditions allow and that
    closes no closed contact node, found by linear programs over the rigid
    modes the conditions leave free. The gap's change along each rigid mode
    is measured (a difference quotient), so rigid obstacles and deformable
    pairs count alike; a frictionless contact holds nothing along it. A
    motion along which the surface tractions do negative work is held too:
    the load presses the body into the contacts that resist it (a block
    pushed onto a floor by a pressure), so the first load step closes them.

    Args:
        domain: the mesh of every body.
        bodies: (name, local cell indices) of each body.
        conditions: (local facet indices, value per component, None free) of
            each Dirichlet condition.
        contact_gaps: the owned nodal gaps of every contact (joined) for a
            displacement given per geometry node, shape (nodes, gdim) (length).
        tractions: (local facet indices, traction at load factor 1) of each
            surface traction.
        touching: the mask of the gaps at the start that count as closed
            (collective; None: those at most 1e-9 of the assembly's size).

    Returns:
        (body name, its part of the motion in words) for each body that the
        free motion found moves; empty when every rigid motion is held.
        Collective.
    """
    return AssemblyModes(domain, bodies, conditions).free_motion(
        contact_gaps, tractions=tractions, touching=touching)


class AssemblyModes:
    """The rigid modes of each body of a mesh and the Dirichlet rows that hold them.

    Built once (the bodies' nodes and the prescribed components at them);
    :meth:`free_motion` then asks which motion the conditions and the
    contacts leave free, at the start (unilateral closed gaps) or in a
    deformed state (the contact nodes closed there, both ways). Collective.

    Args:
        domain: the mesh of every body.
        bodies: (name, local cell indices) of each body.
        conditions: (local facet indices, value per component, None free) of
            each Dirichlet condition.
    """

    def __init__(
        self,
        domain: mesh.Mesh,
        bodies: Sequence[tuple[str, np.ndarray]],
        conditions: Sequence[tuple[np.ndarray, Sequence[float | None]]],
    ) -> None:
        tdim = domain.topology.dim
        self.domain = domain
        self.gdim = domain.geometry.dim
        self.n_modes = 3 if self.gdim == 2 else 6
        self.bodies = list(bodies)
        self.vertices = [
            np.unique(mesh.entities_to_geometry(domain, tdim, cells.astype(np.int32)).ravel())
            for _, cells in self.bodies]
        fverts = [np.unique(mesh.entities_to_geometry(
            domain, tdim - 1, np.asarray(facets, dtype=np.int32)).ravel())
            for facets, _ in conditions]
        #: (body index, geometry nodes, component) of every prescribed component, body by body
        self.held: list[tuple[int, np.ndarray, int]] = []
        for i, verts in enumerate(self.vertices):
            for nodes, (_, value) in zip(fverts, conditions, strict=True):
                on_body = nodes[np.isin(nodes, verts)]
                self.held += [(i, on_body, c) for c, v in enumerate(value)
                              if v is not None and on_body.size]

    def free_modes(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
        """The motions the conditions leave free at positions ``x`` (geometry nodes, length).

        Returns (modes as columns, per body n_modes coefficients in scaled
        coordinates; the centre and size of the scaling). Collective.
        """
        comm = self.domain.comm
        lo, hi = _reduce(comm, x, np.min, MPI.MIN), _reduce(comm, x, np.max, MPI.MAX)
        centre = 0.5 * (lo + hi)
        size = float(np.max(hi - lo)) or 1.0
        n = self.n_modes * len(self.bodies)
        gram = np.zeros((n, n))
        for i, nodes, component in self.held:
            rows = np.zeros((nodes.size, n))
            rows[:, i * self.n_modes:(i + 1) * self.n_modes] = _basis(
                (x[nodes] - centre) / size, component, self.gdim)
            gram += rows.T @ rows
        total = np.empty_like(gram)
        comm.Allreduce(gram, total, op=MPI.SUM)
        eigenvalues, vectors = np.linalg.eigh(total)
        free = vectors[:, eigenvalues <= 1e-10 * max(float(eigenvalues.max()), 1.0)]
        return free, centre, size

    def mode_field(self, x: np.ndarray, mode: np.ndarray, centre: np.ndarray,
                   size: float) -> np.ndarray:
        """The displacement of the geometry nodes by a scaled assembly mode (nodes, gdim)."""
        u = np.zeros_like(x)
        for i, verts in enumerate(self.vertices):
            points = (x[verts] - centre) / size
            part = mode[i * self.n_modes:(i + 1) * self.n_modes]
            u[verts] += np.column_stack(
                [_basis(points, c, self.gdim) @ part for c in range(self.gdim)])
        return u

    def free_motion(
        self,
        contact_values: Callable[[np.ndarray], np.ndarray],
        displacement: np.ndarray | None = None,
        holding: Callable[[np.ndarray], np.ndarray] | None = None,
        tractions: Sequence[tuple[np.ndarray, Sequence[float]]] = (),
        touching: Callable[[np.ndarray], np.ndarray] | None = None,
    ) -> list[tuple[str, str]]:
        """A rigid motion that neither the conditions nor the contacts hold ([] when held).

        Args:
            contact_values: the owned nodal measures of every contact (joined:
                gaps, and the slips of frictional ones, length) for a
                displacement per geometry node, shape (nodes, gdim).
            displacement: the state's displacement per geometry node (None: the
                start, u = 0); the modes are rigid motions of the deformed
                bodies and the measures change from their values there.
            holding: None at the start: the gaps at most 1e-9 size are closed
                and resist only the motions that close them (``contact_values``
                gives gaps alone). In a state: called with the measures there
                (only when the conditions leave a motion free) for the mask of
                those that hold both ways, as the active set of a Newton step does.
            tractions: (local facet indices, traction at load factor 1) of each
                surface traction: at the start a motion they oppose is held.
            touching: at the start, the mask of the gaps that are closed
                (None: at most 1e-9 size).

        Returns:
            (body name, its part of the motion in words) per moving body. Collective.
        """
        x = self.domain.geometry.x[:, :self.gdim]
        start = np.zeros_like(x) if displacement is None else displacement
        x = x + start
        free, centre, size = self.free_modes(x)
        if free.shape[1] == 0:
            return []
        # d measure / d mode at the closed nodes, for the modes the conditions leave free
        step = 1e-7 * size
        base = contact_values(start)
        if holding is not None:
            closed = holding(base)
        else:
            closed = base <= 1e-9 * size if touching is None else touching(base)
        columns = [(contact_values(start + step * self.mode_field(x, free[:, j], centre, size))
                    - base)[closed] / step for j in range(free.shape[1])]
        resist = np.vstack(self.domain.comm.allgather(np.column_stack(columns)))
        if holding is not None:
            if _full_rank(resist):
                return []  # the closed nodes, held both ways, leave no mode free
            resist = np.vstack([resist, -resist])  # a closed node resists both ways
        work = free.T @ _mode_loads(self.domain, self.vertices, tractions, centre, size,
                                    self.n_modes) if tractions else np.zeros(0)
        if np.any(work):
            # the loads' work along a motion: a motion they oppose (negative work) is held
            resist = np.vstack([resist, work / np.abs(work).max()])
        return _name_free_motion(free, resist, self.bodies, centre, size, self.gdim)


def _name_free_motion(free: np.ndarray, resist: np.ndarray,
                      bodies: Sequence[tuple[str, np.ndarray]], centre: np.ndarray,
                      size: float, gdim: int) -> list[tuple[str, str]]:
    """The free motion among the columns of ``free`` that ``resist`` (c >= 0) allows, in words.

    The single free modes first, then what else is free; [] when none.
    """
    pure, coefficients = _pure_free_modes(free, resist, bodies, centre, gdim)
    if pure:
        # what else is free, apart from the pure modes (a rotation about another point)
        rest = _complement(coefficients, free.shape[1])
        c = _lp_free_motion(resist @ rest) if rest.shape[1] else None
        if c is not None:
            extra = dict(_moving_bodies(free @ rest @ c, bodies, centre, size, gdim))
            pure = [(name, f"{what} and {extra[name]}" if name in extra else what)
                    for name, what in pure]
        return pure
    c = _lp_free_motion(resist, free.shape[1])
    return [] if c is None else _moving_bodies(free @ c, bodies, centre, size, gdim)


def _full_rank(resist: np.ndarray) -> bool:
    """Whether two-sided rows leave no combination c that :func:`_lp_free_motion` finds.

    Such a c has |resist c| <= 1e-9 per row and max |c| > 1e-3, so
    |resist c|_2 <= 1e-9 sqrt(rows) while |resist c|_2 >= s_min 1e-3: a
    smallest singular value above 1e-6 sqrt(rows) rules it out (and every
    pure mode, max |c| = 1) without the linear programs, the common case of
    a held body, at a fraction of their cost.
    """
    m, k = resist.shape
    if m < k:
        return False
    return bool(np.linalg.svd(resist, compute_uv=False)[-1] > 1e-6 * np.sqrt(m))


def _mode_loads(domain: mesh.Mesh, vertices: list[np.ndarray],
                tractions: Sequence[tuple[np.ndarray, Sequence[float]]], centre: np.ndarray,
                size: float, n_modes: int) -> np.ndarray:
    """The tractions' work along each rigid mode of each body (scaled modes; collective).

    int t . phi_k dA over each traction's owned facets, phi_k linear and t
    constant: the facet's area times phi_k at its vertices' mean (exact on
    segments and triangles).
    """
    gdim = domain.geometry.dim
    tdim = domain.topology.dim
    x = domain.geometry.x[:, :gdim]
    owned = domain.topology.index_map(tdim - 1).size_local
    out = np.zeros(n_modes * len(vertices))
    for facets, value in tractions:
        facets = np.asarray(facets, np.int32)
        facets = facets[facets < owned]
        if facets.size == 0 or not np.any(value):
            continue
        nodes = mesh.entities_to_geometry(domain, tdim - 1, facets)
        area = _facet_areas(x[nodes])
        centroid = (x[nodes].mean(axis=1) - centre) / size
        for i, verts in enumerate(vertices):
            on = np.isin(nodes[:, 0], verts)
            for c, t in enumerate(value):
                if t:
                    out[i * n_modes:(i + 1) * n_modes] += float(t) * (
                        area[on] @ _basis(centroid[on], c, gdim))
    total = np.empty_like(out)
    domain.comm.Allreduce(out, total, op=MPI.SUM)
    return total


def _facet_areas(points: np.ndarray) -> np.ndarray:
    """Areas of facets (m, vertices, gdim): segments, triangles, quadrilaterals (DOLFINx order)."""
    if points.shape[-1] == 2:
        return np.linalg.norm(points[:, 1] - points[:, 0], axis=-1)
    if points.shape[1] == 3:
        return 0.5 * np.linalg.norm(np.cross(points[:, 1] - points[:, 0],
                                             points[:, 2] - points[:, 0]), axis=-1)
    # a quadrilateral 0, 1, 3, 2 around: half the cross product of its diagonals
    return 0.5 * np.linalg.norm(np.cross(points[:, 3] - points[:, 0],
                                         points[:, 2] - points[:, 1]), axis=-1)


def _complement(columns: list[np.ndarray], k: int) -> np.ndarray:
    """An orthonormal basis (k, m) of the complement of ``columns`` in R^k."""
    if not columns:
        return np.eye(k)
    q, r = np.linalg.qr(np.column_stack(columns), mode="complete")
    rank = int(np.sum(np.abs(np.diag(r)) > 1e-10))
    return q[:, rank:]


def _lp_free_motion(resist: np.ndarray, k: int | None = None) -> np.ndarray | None:
    """Coefficients c of a motion with resist c >= 0 (no closed node closes) and c != 0.

    Linear programs along each axis of the coefficients (bounds +-1); None
    when every motion closes some closed node.
    """
    from scipy.optimize import linprog

    k = resist.shape[1] if k is None else k
    for j in range(k):
        for sign in (1.0, -1.0):
            objective = np.zeros(k)
            objective[j] = -sign
            # a closing rate below 1e-9 (scaled) is the difference quotient's noise;
            # a free motion reaches the bounds (+-1), a held one stays near 0
            result = linprog(objective, A_ub=-resist if resist.size else None,
                             b_ub=np.full(resist.shape[0], 1e-9) if resist.size else None,
                             bounds=[(-1.0, 1.0)] * k, method="highs")
            if result.status == 0 and -result.fun > 1e-3:
                return result.x
    return None


def _pure_free_modes(free: np.ndarray, resist: np.ndarray,
                     bodies: Sequence[tuple[str, np.ndarray]], centre: np.ndarray,
                     gdim: int) -> tuple[list[tuple[str, str]], list[np.ndarray]]:
    """The single rigid modes (a translation along an axis, a rotation about the centre) free.

    Named first, each of them: a ring between two plates without a cut is
    free to slide in x and to turn, and a mix of the two (a rotation about a
    point below it) named only one of them. Per body, its free modes joined;
    also the coefficients (in the columns of ``free``) of each mode found.
    """
    n_modes = 3 if gdim == 2 else 6
    names = _names(gdim)
    out, coefficients = [], []
    for i, (name, _) in enumerate(bodies):
        motions = []
        for k in range(n_modes):
            e = np.zeros(free.shape[0])
            e[i * n_modes + k] = 1.0
            c = free.T @ e
            if np.linalg.norm(free @ c - e) > 1e-8:
                continue  # a condition holds it
            closing = resist @ c if resist.size else np.zeros(0)
            if np.all(closing >= -1e-9) or np.all(closing <= 1e-9):
                motions.append(names[k] + (f" about ({_fmt(centre)})" if "rotation" in names[k]
                                           and gdim == 2 else ""))
                coefficients.append(c)
        if motions:
            out.append((name, " and ".join(motions)))
    return out, coefficients


def _moving_bodies(mode: np.ndarray, bodies: Sequence[tuple[str, np.ndarray]],
                   centre: np.ndarray, size: float, gdim: int) -> list[tuple[str, str]]:
    """Each body that a rigid motion of the assembly (modes per body, scaled) moves, in words."""
    n_modes = 3 if gdim == 2 else 6
    parts = mode.reshape(len(bodies), n_modes)
    scale = float(np.max(np.linalg.norm(parts, axis=1)))
    out = []
    names = _names(gdim)
    for (name, _), part in zip(bodies, parts, strict=True):
        if np.linalg.norm(part) <= 1e-3 * scale:
            continue
        part = part / np.linalg.norm(part)
        part = np.where(np.abs(part) < 1e-6, 0.0, part)  # the linear program's round-off
        pure = np.flatnonzero(part)
        if pure.size == 1 and "translation" in names[pure[0]]:
            out.append((name, names[pure[0]]))
        else:
            out.append((name, _describe(part, centre, size, gdim)))
    return out


def _reduce(comm: MPI.Comm, x: np.ndarray, local: Callable, op: MPI.Op) -> np.ndarray:
    """Per-axis min or max of the coordinates over the ranks."""
    gdim = x.shape[1]
    fill = np.inf if op == MPI.MIN else -np.inf
    # along the rows of x^T: numpy reduces an (n, 2) array over axis 0 ten times slower
    mine = local(np.ascontiguousarray(x.T), axis=1) if x.size else np.full(gdim, fill)
    out = np.empty(gdim)
    comm.Allreduce(np.ascontiguousarray(mine, dtype=float), out, op=op)
    return out
