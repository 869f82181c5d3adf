"""The target surface of a node-to-segment pair as one rank needs it: the facets near its strikers.

Each rank owns the target facets of its part of the mesh. With
``keep_all=False`` a rank keeps (holds and searches) only the target facets
whose bounding box meets its *kept box* B: the bounding box of its own
striker nodes enlarged by a reach (length). The owners send those facets
(global V blocks, reference positions) in one all-to-all exchange, and the
displacements of the kept vertices come from the owners of their V blocks
through one PETSc scatter per use: no rank ever holds the whole target
surface or its displacements.

The search over the kept facets is the search over the whole surface as
long as no striker node can be as close to a facet outside B as to its best
kept facet (:meth:`TargetSurface.covers`): every facet left out lay, at the
last exchange, inside the target's bounding box T but outside B, and has
moved since by at most delta (the largest change of a target vertex's
displacement since then). A node at distance d from its best kept facet is
settled when d + tol < dist(node, T minus B) - delta. When a node is not
settled, B grows (it never shrinks, so kept facets stay kept) by the
smallest reach that settles every node, and the facets are exchanged again.

``keep_all=True`` keeps every facet on every rank (the self-contact search,
which needs the whole surface).

Each facet travels with its *free sides*: the sides (2D: end vertices; 3D:
edges) that no other facet of the whole target surface shares, its rim.
They are counted once over all ranks, so a kept facet's side is free only
where the target surface really ends, not where the kept part does.
"""

from __future__ import annotations

import numpy as np
from dolfinx import fem

from mpi4py import MPI
from petsc4py import PETSc

#: Reach of the first exchange and added margin of the later ones, in the
#: target's largest facet size: room for the motion between exchanges.
REACH_FACETS = 2.0
#: Growth factor of the trial reaches when some node is not settled.
GROWTH = 1.5


def free_sides(blocks: np.ndarray, comm: MPI.Comm) -> np.ndarray:
    """Which sides of each facet no other facet of the surface shares (collective).

    Args:
        blocks: (m, nv) global V blocks of the vertices of this rank's facets.
        comm: the communicator the surface's facets are spread over.

    Returns:
        (m, nv) bool. Side k: 2D the end vertex k, 3D the edge opposite vertex k.
    """
    m, nv = blocks.shape
    sides = [(k,) for k in range(2)] if nv == 2 else [((k + 1) % 3, (k + 2) % 3) for k in range(3)]
    keys = np.stack([np.sort(blocks[:, list(v)], axis=1) for v in sides], axis=1)
    keys = keys.reshape(m * nv, len(sides[0]))  # one row per (facet, side)
    if comm.size == 1:
        _, inverse, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
        return (counts[inverse.reshape(-1)] == 1).reshape(m, nv)
    # each side is counted on the rank its first vertex hashes to
    owner = keys[:, 0] % comm.size
    order = np.argsort(owner, kind="stable")
    sent = comm.alltoall([keys[order[owner[order] == r]] for r in range(comm.size)])
    got = np.concatenate(sent) if sent else np.zeros((0, keys.shape[1]), np.int64)
    if got.shape[0]:
        _, inverse, counts = np.unique(got, axis=0, return_inverse=True, return_counts=True)
        once = counts[inverse.reshape(-1)] == 1
    else:
        once = np.zeros(0, bool)
    sizes = np.cumsum([0, *(a.shape[0] for a in sent)])
    back = comm.alltoall([once[sizes[r]:sizes[r + 1]] for r in range(comm.size)])
    free = np.zeros(m * nv, bool)
    free[order] = np.concatenate(back) if back else np.zeros(0, bool)
    return free.reshape(m, nv)


def _outside_distance(points: np.ndarray, target: np.ndarray, box: np.ndarray) -> np.ndarray:
    """Distance (length) from each point to the part of box ``target`` outside box ``box``.

    Boxes are (2, gdim) arrays (low, high corners). The part outside is the
    union of at most 2 gdim slabs of ``target``; inf where it is empty.
    """
    out = np.full(points.shape[0], np.inf)
    for i in range(points.shape[1]):
        for side in (0, 1):
            lo, hi = target[0].copy(), target[1].copy()
            if side == 0 and target[0, i] < box[0, i]:
                hi[i] = min(hi[i], box[0, i])
            elif side == 1 and target[1, i] > box[1, i]:
                lo[i] = max(lo[i], box[1, i])
            else:
                continue  # no target beyond this face of the box
            gap = np.maximum(np.maximum(lo - points, points - hi), 0.0)
            out = np.minimum(out, np.linalg.norm(gap, axis=1))
    return out


class TargetSurface:
    """The target facets one rank keeps, with their vertices and displacements.

    Args:
        V: the displacement space (vector P1).
        local_blocks: (m, nv) local V blocks of the vertices of the facets this
            rank owns, oriented (the vertex order gives the outward normal).
        X: (m, nv, gdim) reference positions of those vertices (length).
        keep_all: keep every facet on every rank instead of those near the
            rank's striker nodes.

    Attributes (of the kept facets, in the order of their global index):
        gid: global facet index (owner's rank order, then owner's local order).
        blocks: (k, nv) global V blocks of their vertices.
        vertices: the distinct global V blocks; ``facet_vertex`` indexes them.
        X_vertices: (len(vertices), gdim) reference positions (length).
        free: (k, nv) bool, the free sides of each kept facet (:func:`free_sides`).
        gathers: how many exchanges were made.
    """

    def __init__(self, V: fem.FunctionSpace, local_blocks: np.ndarray, X: np.ndarray,
                 keep_all: bool = False) -> None:
        comm = V.mesh.comm
        self.comm = comm
        self.V = V
        self.keep_all = keep_all
        self.gdim = X.shape[2] if X.ndim == 3 else V.mesh.geometry.dim
        self.nv = local_blocks.shape[1]
        m = local_blocks.shape[0]
        im = V.dofmap.index_map
        self._own_local = np.asarray(local_blocks, np.int32)
        self._own_blocks = (
            im.local_to_global(self._own_local.reshape(-1)).reshape(m, self.nv).astype(np.int64)
            if m else np.zeros((0, self.nv), np.int64)
        )
        self._own_X = np.asarray(X, float).reshape(m, self.nv, self.gdim)
        self._own_gid = (comm.exscan(m) or 0) + np.arange(m, dtype=np.int64)
        self._own_free = free_sides(self._own_blocks, comm)
        self.num_global = comm.allreduce(m)
        self._own_vertex = np.unique(self._own_local)
        self._own_vertex_X = np.zeros((self._own_vertex.size, self.gdim))
        pos = np.searchsorted(self._own_vertex, self._own_local.reshape(-1))
        self._own_vertex_X[pos] = self._own_X.reshape(-1, self.gdim)
        self._own_facet_vertex = pos.reshape(m, self.nv)
        self.gid = np.zeros(0, np.int64)
        self.blocks = np.zeros((0, self.nv), np.int64)
        self._X = np.zeros((0, self.nv, self.gdim))
        self.free = np.zeros((0, self.nv), bool)
        self.box: np.ndarray | None = None
        self.gathers = 0
        self._scatter: PETSc.Scatter | None = None
        self._seq: PETSc.Vec | None = None
        self._u0 = np.zeros((self._own_vertex.size, self.gdim))
        self._target_box = np.zeros((2, self.gdim))

    # -- the owned facets -----------------------------------------------------------
    def own_current(self, u: fem.Function) -> np.ndarray:
        """Current positions (m, nv, gdim) of the owned facets' vertices (length)."""
        w = u.x.array.reshape(-1, self.gdim)[self._own_vertex]
        return (self._own_vertex_X + w)[self._own_facet_vertex]

    def facet_size(self, u: fem.Function) -> float:
        """Largest first edge |x_1 - x_0| over the whole current surface (length; collective)."""
        cur = self.own_current(u)
        local = float(np.max(np.linalg.norm(cur[:, 1] - cur[:, 0], axis=-1), initial=0.0))
        return self.comm.allreduce(local, op=MPI.MAX)

    def motion(self, u: fem.Function) -> float:
        """Largest change of a target vertex's displacement since the last exchange (collective)."""
        w = u.x.array.reshape(-1, self.gdim)[self._own_vertex]
        local = float(np.max(np.linalg.norm(w - self._u0, axis=1), initial=0.0))
        return self.comm.allreduce(local, op=MPI.MAX)

    # -- the exchange ------------------------------------------------------------------
    def gather(self, points: np.ndarray, reach: float, u: fem.Function) -> None:
        """Grow the kept box to hold ``points`` enlarged by ``reach`` and exchange (collective).

        Args:
            points: (n, gdim) current positions of this rank's striker nodes.
            reach: enlargement of their bounding box (length).
            u: the displacement (current facet positions).
        """
        gd = self.gdim
        if self.keep_all:
            box = np.array([np.full(gd, -np.inf), np.full(gd, np.inf)])
        elif points.shape[0]:
            box = np.array([points.min(axis=0) - reach, points.max(axis=0) + reach])
        else:
            box = np.array([np.full(gd, np.inf), np.full(gd, -np.inf)])  # empty
        if self.box is not None:
            box = np.array([np.minimum(box[0], self.box[0]), np.maximum(box[1], self.box[1])])
        self.box = box
        boxes = self.comm.allgather(box)
        cur = self.own_current(u)
        lo, hi = cur.min(axis=1), cur.max(axis=1)
        send = []
        for other in boxes:
            hit = np.flatnonzero(np.all((hi >= other[0]) & (lo <= other[1]), axis=1))
            send.append((self._own_gid[hit], self._own_blocks[hit], self._own_X[hit],
                         self._own_free[hit]))
        got = self.comm.alltoall(send)
        self._keep(np.concatenate([self.gid, *(g[0] for g in got)]),
                   np.concatenate([self.blocks, *(g[1] for g in got)]),
                   np.concatenate([self._X, *(g[2] for g in got)]),
                   np.concatenate([self.free, *(g[3] for g in got)]))
        tlo = lo.min(axis=0) if lo.size else np.full(gd, np.inf)
        thi = hi.max(axis=0) if hi.size else np.full(gd, -np.inf)
        box_lo, box_hi = np.empty(gd), np.empty(gd)
        self.comm.Allreduce(np.ascontiguousarray(tlo, float), box_lo, op=MPI.MIN)
        self.comm.Allreduce(np.ascontiguousarray(thi, float), box_hi, op=MPI.MAX)
        self._target_box = np.array([box_lo, box_hi])
        self._u0 = u.x.array.reshape(-1, gd)[self._own_vertex].copy()
        self._make_scatter(u)
        self.gathers += 1

    def _keep(self, gid: np.ndarray, blocks: np.ndarray, X: np.ndarray,
              free: np.ndarray) -> None:
        """Keep these facets (repeats dropped), numbered by global index."""
        gid, first = np.unique(gid, return_index=True)  # kept facets stay kept
        self.gid, self.blocks, self._X, self.free = gid, blocks[first], X[first], free[first]
        self.vertices, inverse = np.unique(self.blocks, return_inverse=True)
        self.facet_vertex = inverse.reshape(-1, self.nv)
        self.X_vertices = np.zeros((self.vertices.size, self.gdim))
        self.X_vertices[self.facet_vertex.reshape(-1)] = self._X.reshape(-1, self.gdim)

    # -- a resumed run ---------------------------------------------------------------------
    def kept_state(self) -> dict[str, np.ndarray]:
        """What the exchanges so far left: the kept facets, the box, the last exchange's state.

        Local arrays of this rank; :meth:`restore_kept` puts them back.
        """
        box = np.full((2, self.gdim), np.nan) if self.box is None else self.box
        return {"gid": self.gid.copy(), "box": np.array(box, float),
                "target_box": self._target_box.copy(), "u0": self._u0.copy()}

    def restore_kept(self, state: dict[str, np.ndarray], u: fem.Function) -> None:
        """Keep exactly the facets of a :meth:`kept_state` (collective; a resumed run).

        Each facet is asked of the rank that owns it, so the kept set, its
        numbering and the motion since the last exchange are those of the run
        that wrote the state (a fresh exchange keeps what the box reaches at
        the current u, which may be other facets).
        """
        gid = np.asarray(state["gid"], np.int64)
        counts = np.asarray(self.comm.allgather(self._own_gid.size), np.int64)
        ends = np.cumsum(counts)
        owner = np.searchsorted(ends, gid, side="right")
        asked = self.comm.alltoall([gid[owner == r] for r in range(self.comm.size)])
        start = ends[self.comm.rank] - counts[self.comm.rank]
        send = []
        for wanted in asked:
            k = np.asarray(wanted, np.int64) - start
            send.append((self._own_gid[k], self._own_blocks[k], self._own_X[k],
                         self._own_free[k]))
        got = self.comm.alltoall(send)
        self._keep(np.concatenate([np.zeros(0, np.int64), *(g[0] for g in got)]),
                   np.concatenate([np.zeros((0, self.nv), np.int64), *(g[1] for g in got)]),
                   np.concatenate([np.zeros((0, self.nv, self.gdim)), *(g[2] for g in got)]),
                   np.concatenate([np.zeros((0, self.nv), bool), *(g[3] for g in got)]))
        box = np.asarray(state["box"], float)
        self.box = None if np.isnan(box).any() else box.copy()
        self._target_box = np.asarray(state["target_box"], float).copy()
        self._u0 = np.asarray(state["u0"], float).reshape(self._u0.shape).copy()
        self._make_scatter(u)
        self.gathers += 1

    def _make_scatter(self, u: fem.Function) -> None:
        """The scatter of the kept vertices' V blocks from their owners into a local vector."""
        for obj in (self._scatter, self._seq):
            if obj is not None:
                obj.destroy()
        bs = self.gdim
        index = PETSc.IS().createBlock(bs, self.vertices.astype(PETSc.IntType),
                                       comm=PETSc.COMM_SELF)
        self._seq = PETSc.Vec().createSeq(self.vertices.size * bs, bsize=bs, comm=PETSc.COMM_SELF)
        self._scatter = PETSc.Scatter().create(u.x.petsc_vec, index, self._seq, None)
        index.destroy()

    def displacements(self, u: fem.Function) -> np.ndarray:
        """(len(vertices), gdim) displacements of the kept vertices in ``u`` (collective)."""
        self._scatter.scatter(u.x.petsc_vec, self._seq, addv=PETSc.InsertMode.INSERT,
                              mode=PETSc.ScatterMode.FORWARD)
        return self._seq.getArray(readonly=True).reshape(-1, self.gdim).copy()

    # -- the guarantee -------------------------------------------------------------------
    def settled(self, points: np.ndarray, distance: np.ndarray, tol: float, motion: float,
                box: np.ndarray | None = None) -> np.ndarray:
        """Which points no left-out facet can reach within ``distance + tol`` (length).

        ``box``: a trial kept box (default: the current one).
        """
        if self.keep_all:
            return np.ones(points.shape[0], bool)
        outside = _outside_distance(points, self._target_box, self.box if box is None else box)
        return distance + tol < outside - motion

    def covers(self, points: np.ndarray, distance: np.ndarray, tol: float,
               motion: float) -> bool:
        """True when every rank's kept facets settle all its points (collective)."""
        ok = bool(np.all(self.settled(points, distance, tol, motion)))
        return self.keep_all or self.comm.allreduce(ok, op=MPI.LAND)

    def reach_for(self, points: np.ndarray, distance: np.ndarray, tol: float,
                  margin: float) -> float:
        """The smallest trial reach (margin * GROWTH^j) whose box settles every point (length).

        Judged against the target's box of the last exchange, with ``margin``
        added to every distance for the motion until the next exchange.
        """
        reach = margin
        if points.shape[0] == 0:
            return reach
        lo, hi = points.min(axis=0), points.max(axis=0)
        for _ in range(200):
            box = np.array([np.minimum(lo - reach, self.box[0]),
                            np.maximum(hi + reach, self.box[1])])
            if np.all(self.settled(points, distance + margin, tol, 0.0, box)):
                return reach
            reach *= GROWTH
        return np.inf

    def destroy(self) -> None:
        """Free the scatter."""
        for obj in (self._scatter, self._seq):
            if obj is not None:
                obj.destroy()
