"""Type stub of the extension module (re-exported by ``proxima``)."""

import os
from typing import Final, Literal, TypedDict

import numpy as np
from numpy.typing import ArrayLike, NDArray

IndexKind = Literal["brute", "loose-kd", "octree", "grid2d", "hashgrid", "grid3d"]
BoundingVolume = Literal["aabb", "kdop14", "kdop18", "kdop26", "obb", "sphere"]

INDEX_KINDS: Final[list[str]]
"""The index kinds, brute force (the oracle) first."""
BOUNDING_VOLUMES: Final[list[str]]
"""The bounding volumes a :class:`Mesh` can use."""

class Index:
    """A broad-phase index over bounding spheres: one of the six built-in
    indices, chosen by name.

    Objects are named by integer **ids**: row ``i`` of the arrays the index was
    built from is id ``i``, and each later insert takes the next unused id, so
    ids are insertion order (as row numbers are for scipy's ``cKDTree`` and
    geometry ids for Open3D). An id is never reused: after ``remove`` or
    ``clear`` it raises ``KeyError``. Every query returns ids, so
    ``centers[ids]`` selects from the arrays the index was built from.

    Numbers are stored as float32 (float64 input is rounded); overlap is closed
    (touching counts) and exact for the stored values. Batch queries return
    ``(ids, offsets)``: query ``i`` selected ``ids[offsets[i]:offsets[i+1]]``.
    ``workers``: 1 (this thread), n (a pool of n threads) or -1 (one per core).
    """

    def __init__(
        self,
        centers: ArrayLike | None = None,
        radii: ArrayLike | float | None = None,
        *,
        kind: IndexKind = "grid3d",
        world: ArrayLike | None = None,
        r_max: float | None = None,
    ) -> None:
        """Builds an index of ``kind`` holding the spheres ``centers`` (N, 3)
        with ``radii`` (N,) or one radius for all; row i gets id i.

        The index is tuned from the spheres (their box and the 99th percentile
        of the radii) unless ``world`` ([min, max] as (2, 3) or (6,)) and
        ``r_max`` (a typical large radius) say otherwise: give both when
        building an empty index that is filled by ``insert`` later. Any sphere
        is accepted, inside the world or not; the hint only tunes speed.

        Raises ValueError on an unknown kind, a wrong shape, a non-finite value
        or a negative radius.
        """

    @property
    def kind(self) -> str:
        """The index's kind ("grid3d", ...)."""

    @property
    def memory_bytes(self) -> int:
        """Bytes held by the index and its id table."""

    def __len__(self) -> int:
        """Number of stored objects."""

    def __contains__(self, id: object) -> bool:
        """Whether ``id`` names a stored object."""

    def insert(self, center: ArrayLike, radius: float) -> int:
        """Stores one sphere and returns its id."""

    def insert_many(self, centers: ArrayLike, radii: ArrayLike | float) -> NDArray[np.int64]:
        """Stores spheres ``centers`` (K, 3) with ``radii`` (K,) or one radius;
        returns their ids (K,), consecutive. All or nothing: a bad row raises
        ValueError naming it and stores nothing."""

    def remove(self, id: int) -> None:
        """Removes an object. KeyError if ``id`` is not stored."""

    def remove_many(self, ids: ArrayLike) -> None:
        """Removes every object of ``ids``. All or nothing: KeyError, removing
        nothing, if one is not stored or appears twice."""

    def update(self, id: int, center: ArrayLike, radius: float | None = None) -> None:
        """Moves (and with ``radius``, resizes) one object. KeyError if ``id``
        is not stored; ValueError on a bad sphere (nothing changes)."""

    def update_many(
        self,
        ids: ArrayLike | None,
        centers: ArrayLike,
        radii: ArrayLike | float | None = None,
    ) -> None:
        """Moves objects ``ids`` (K,) to ``centers`` (K, 3), resized to
        ``radii`` (K,) or one radius if given (otherwise they keep theirs).
        ``ids=None`` means ids 0..K-1 (every object of an index built from K
        rows). All or nothing: a stale id (KeyError) or a bad row (ValueError)
        changes nothing. Releases the GIL."""

    def get(self, id: int) -> tuple[NDArray[np.float32], float]:
        """The centre (3,) and radius of one object. KeyError if not stored."""

    def ids(self) -> NDArray[np.int64]:
        """The ids of the stored objects, ascending."""

    def spheres(
        self, ids: ArrayLike | None = None
    ) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
        """``(centers (K, 3), radii (K,))`` of ``ids`` (default: every stored
        object by ascending id). KeyError on an id not stored."""

    def clear(self) -> None:
        """Removes every object (their ids raise KeyError from now on; new
        inserts continue after the last id issued)."""

    def validate(self) -> None:
        """Checks the structure's invariants (RuntimeError if one fails: a bug)."""

    def query_spheres(
        self, spheres: ArrayLike, *, workers: int = 1
    ) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """Objects overlapping each sphere of ``spheres`` (M, 4): centre x, y,
        z, radius (also the point-radius query). Returns ``(ids, offsets)``,
        each query's ids ascending. One (4,) row is a batch of one."""

    def query_boxes(
        self, boxes: ArrayLike, *, workers: int = 1
    ) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """Objects overlapping each box of ``boxes`` (M, 6): min x, y, z, max
        x, y, z. Returns ``(ids, offsets)``, each query's ids ascending."""

    def query_rays(
        self,
        rays: ArrayLike,
        tmax: ArrayLike | float | None = None,
        *,
        return_t: bool = False,
        workers: int = 1,
    ) -> tuple[NDArray[np.int64], NDArray[np.int64]] | tuple[
        NDArray[np.int64], NDArray[np.int64], NDArray[np.float32]
    ]:
        """Objects each ray touches for some t in [0, tmax]: ``rays`` (M, 6),
        origin x, y, z and direction x, y, z (any non-zero length; t is in its
        units), ``tmax`` a scalar or (M,), inf by default. Returns ``(ids,
        offsets)`` with each ray's hits in order along it (entry t, 0 if the
        origin is inside; ties by id), and with ``return_t=True`` also ``t``
        (float32) beside ``ids``."""

    def ray_first(
        self, rays: ArrayLike, tmax: ArrayLike | float | None = None, *, workers: int = 1
    ) -> tuple[NDArray[np.int64], NDArray[np.float32]]:
        """The first object each ray enters (smallest entry t; between equal t,
        one of them): ``(ids (M,), t (M,))``, -1 and inf for a miss."""

    def query_frusta(
        self,
        matrices: ArrayLike,
        *,
        depth: Literal["zero_to_one", "minus_one_to_one"] = "zero_to_one",
        workers: int = 1,
    ) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """Objects inside each view frustum: ``matrices`` (M, 4, 4)
        view-projection matrices (projection @ view, acting on column vectors
        (x, y, z, 1)). ``depth`` is the projection's clip-space depth range:
        "zero_to_one" (Direct3D, Vulkan, Metal, wgpu) or "minus_one_to_one"
        (OpenGL). A sphere is culled only when it lies entirely outside one of
        the six planes. Returns ``(ids, offsets)``, each query's ids ascending."""

    def pairs(self, *, sort: bool = True, workers: int = 1) -> NDArray[np.int64]:
        """Every overlapping pair of stored objects once, (P, 2) ids with the
        smaller first; rows sorted unless ``sort=False`` (cheaper)."""

class RayCastResult(TypedDict):
    """The answer of :meth:`Mesh.cast_rays` (Open3D's names)."""

    t_hit: NDArray[np.float32]
    """(R,) hit parameter, inf for a miss."""
    primitive_ids: NDArray[np.int64]
    """(R,) triangle hit (row of ``faces``), -1 for a miss."""
    primitive_uvs: NDArray[np.float32]
    """(R, 2) barycentrics (u, v) of the hit point (1-u-v)·a + u·b + v·c."""

class Mesh:
    """A triangle mesh with its collision BVH and ray BVH.

    ``bv`` picks the collision tree's bounding volume: "kdop18" (default),
    "kdop14", "kdop26", "aabb", "obb" or "sphere"; two meshes collide only if
    they use the same one. Vertices are stored as float32. Triangle indices
    (``primitive_ids``, the pairs of :func:`collide`) are rows of ``faces``,
    i.e. the file's order.
    """

    def __init__(
        self,
        vertices: ArrayLike,
        faces: ArrayLike,
        *,
        bv: BoundingVolume = "kdop18",
        split: Literal["sah", "mean", "median"] = "sah",
        leaf_size: int = 1,
    ) -> None:
        """A mesh of ``vertices`` (V, 3) floats and ``faces`` (F, 3) vertex
        indices (any integer dtype). Raises ValueError on a wrong shape or
        dtype, a non-finite vertex, an index out of range, or no faces."""

    @staticmethod
    def load(
        path: str | os.PathLike[str],
        *,
        bv: BoundingVolume = "kdop18",
        split: Literal["sah", "mean", "median"] = "sah",
        leaf_size: int = 1,
    ) -> Mesh:
        """Reads an OBJ, STL or PLY file (by extension or content).
        FileNotFoundError / PermissionError / OSError if it cannot be read;
        ValueError, naming the file and line or byte offset, if malformed."""

    @property
    def bv(self) -> str:
        """The collision tree's bounding volume."""

    @property
    def n_triangles(self) -> int:
        """Number of triangles."""

    @property
    def n_vertices(self) -> int:
        """Number of vertices."""

    @property
    def vertices(self) -> NDArray[np.float32]:
        """A copy of the vertices, (V, 3)."""

    @property
    def faces(self) -> NDArray[np.int64]:
        """A copy of the triangles, (F, 3) vertex indices."""

    @property
    def aabb(self) -> NDArray[np.float32]:
        """The box of every triangle corner, (2, 3): [min, max]."""

    @property
    def bounding_sphere(self) -> tuple[NDArray[np.float32], float]:
        """A sphere containing every triangle corner: (center (3,), radius)."""

    def set_vertices(self, vertices: ArrayLike) -> None:
        """Moves the vertices (same count and faces) and refits both trees.
        ValueError, changing nothing, on a wrong count or a non-finite vertex."""

    def cast_rays(
        self,
        rays: ArrayLike,
        tmax: ArrayLike | float | None = None,
        *,
        pose: ArrayLike | None = None,
        workers: int = 1,
    ) -> RayCastResult:
        """The closest hit of each ray, exact: ``rays`` (R, 6), origin and
        direction, up to ``tmax`` (a scalar or (R,), inf by default). With
        ``pose`` ((4, 4) or (3, 4) rigid) the mesh is placed at ``pose`` and
        the rays are in the world frame. Between triangles hit at the same t,
        the smaller index."""

class Contacts:
    """The answer of :func:`collide` for N poses (N = 1 for a single pose).
    ``len(contacts)`` is N, ``contacts[i]`` the (K_i, 2) pairs of pose i, and
    ``bool(contacts)`` whether any pose collides."""

    @property
    def pairs(self) -> NDArray[np.int64]:
        """(K, 2) intersecting triangle pairs (triangle of a, triangle of b),
        pose after pose; with ``first=True`` at most one per pose."""

    @property
    def offsets(self) -> NDArray[np.int64]:
        """(N + 1,): pose i's pairs are ``pairs[offsets[i]:offsets[i+1]]``."""

    @property
    def colliding(self) -> NDArray[np.bool_]:
        """(N,) whether pose i has an intersecting pair."""

    @property
    def counters(self) -> NDArray[np.uint64]:
        """(N, 3) cost counters per query: nv (bounding-volume pair tests),
        np (triangle pair tests), nu (volume updates for the pose)."""

    def __len__(self) -> int: ...
    def __bool__(self) -> bool: ...
    def __getitem__(self, i: int) -> NDArray[np.int64]: ...

def collide(
    a: Mesh,
    b: Mesh,
    poses: ArrayLike,
    *,
    first: bool = False,
    rotation: Literal["auto", "refit", "conservative"] = "auto",
    workers: int = 1,
) -> Contacts:
    """Which triangles of mesh ``a``, moved by each pose, intersect which
    triangles of mesh ``b`` (at the identity), exactly.

    ``poses``: one rigid pose, (4, 4) or (3, 4) ``[R | t]``, or a batch
    (N, 4, 4) or (N, 3, 4); for two world poses pass ``inv(pose_b) @ pose_a``.
    ``first=True`` stops each query at its first intersecting pair. Raises
    ValueError on a wrong shape, a non-finite value, a pose that is not rigid
    (naming it), or meshes with different bounding volumes; all poses are
    checked before any work. Releases the GIL.
    """
