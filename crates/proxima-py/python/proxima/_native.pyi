"""Type stub of the extension module (re-exported by ``proxima``)."""

import os
from typing import Final, Literal, TypedDict, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

IndexKind = Literal["brute", "loose-kd", "octree", "grid2d", "hashgrid", "grid3d"]
Metric = Literal["surface", "center"]
QueryFilter = tuple[int, int] | None
"""A query's ``filter=``: None (every object) or ``(group, mask)`` bit sets."""
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

    Each object carries a collision filter, ``group`` and ``mask`` bit sets
    in 0..2**32 (default every bit): ``pairs()`` reports two objects only if
    each one's group meets the other's mask, and every query given
    ``filter=(group, mask)`` reports only the objects whose filter interacts
    with that pair the same way (Box2D's, Bullet's and Rapier's scheme).
    """

    def __init__(
        self,
        centers: ArrayLike | None = None,
        radii: ArrayLike | float | None = None,
        *,
        kind: IndexKind = "grid3d",
        world: ArrayLike | None = None,
        r_max: float | None = None,
        group: ArrayLike | int | None = None,
        mask: ArrayLike | int | None = None,
    ) -> None:
        """Builds an index of ``kind`` holding the spheres ``centers`` (N, 3)
        with ``radii`` (N,) or one radius for all; row i gets id i.

        The index is tuned from the spheres (their box and the 99th percentile
        of the radii) unless ``world`` ([min, max] as (2, 3) or (6,)) and
        ``r_max`` (a typical large radius) say otherwise: give both when
        building an empty index that is filled by ``insert`` later. Any sphere
        is accepted, inside the world or not; the hint only tunes speed.
        ``group`` / ``mask``: the objects' collision filters, one integer for
        all or (N,) integers (default every bit).

        Raises ValueError on an unknown kind, a wrong shape, a non-finite value,
        a negative radius or filter bits outside 0..2**32.
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

    def insert(
        self, center: ArrayLike, radius: float, *, group: int | None = None, mask: int | None = None
    ) -> int:
        """Stores one sphere with collision filter ``group`` / ``mask``
        (default every bit) and returns its id."""

    def insert_many(
        self,
        centers: ArrayLike,
        radii: ArrayLike | float,
        *,
        group: ArrayLike | int | None = None,
        mask: ArrayLike | int | None = None,
    ) -> NDArray[np.int64]:
        """Stores spheres ``centers`` (K, 3) with ``radii`` (K,) or one radius
        and filters ``group`` / ``mask`` (each one integer or (K,)); returns
        their ids (K,), consecutive. All or nothing: a bad row raises
        ValueError naming it and stores nothing."""

    def set_filter(
        self, ids: ArrayLike | int, *, group: ArrayLike | int, mask: ArrayLike | int
    ) -> None:
        """Sets the collision filter of ``ids`` (one id or (K,)); ``group`` and
        ``mask`` each one integer or (K,). All or nothing: KeyError on an id
        not stored, ValueError on bits outside 0..2**32."""

    def filter(self, id: int) -> tuple[int, int]:
        """An object's collision filter as ``(group, mask)``. KeyError if not
        stored."""

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
        self, spheres: ArrayLike, *, filter: QueryFilter = None, workers: int = 1
    ) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """Objects overlapping each sphere of ``spheres`` (M, 4): centre x, y,
        z, radius (also the point-radius query). Returns ``(ids, offsets)``,
        each query's ids ascending. One (4,) row is a batch of one.
        ``filter``: only the objects whose filter interacts with ``(group,
        mask)`` (the same on every query)."""

    def query_boxes(
        self, boxes: ArrayLike, *, filter: QueryFilter = None, workers: int = 1
    ) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """Objects overlapping each box of ``boxes`` (M, 6): min x, y, z, max
        x, y, z. Returns ``(ids, offsets)``, each query's ids ascending."""

    def query_rays(
        self,
        rays: ArrayLike,
        tmax: ArrayLike | float | None = None,
        *,
        return_t: bool = False,
        filter: QueryFilter = None,
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
        self,
        rays: ArrayLike,
        tmax: ArrayLike | float | None = None,
        *,
        filter: QueryFilter = None,
        workers: int = 1,
    ) -> tuple[NDArray[np.int64], NDArray[np.float32]]:
        """The first object each ray enters (smallest entry t; between equal t,
        one of them): ``(ids (M,), t (M,))``, -1 and inf for a miss."""

    def query_frusta(
        self,
        matrices: ArrayLike,
        *,
        depth: Literal["zero_to_one", "minus_one_to_one"] = "zero_to_one",
        filter: QueryFilter = None,
        workers: int = 1,
    ) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """Objects inside each view frustum: ``matrices`` (M, 4, 4)
        view-projection matrices (projection @ view, acting on column vectors
        (x, y, z, 1)). ``depth`` is the projection's clip-space depth range:
        "zero_to_one" (Direct3D, Vulkan, Metal, wgpu) or "minus_one_to_one"
        (OpenGL). A sphere is culled only when it lies entirely outside one of
        the six planes. Returns ``(ids, offsets)``, each query's ids ascending."""

    def pairs(self, *, sort: bool = True, workers: int = 1) -> NDArray[np.int64]:
        """Every overlapping pair of stored objects whose filters interact,
        once, (P, 2) ids with the smaller first; rows sorted unless
        ``sort=False`` (cheaper)."""

    @overload
    def nearest(
        self,
        points: ArrayLike,
        k: Literal[1] = 1,
        *,
        distance_upper_bound: float = ...,
        metric: Metric = "surface",
        filter: QueryFilter = None,
        workers: int = 1,
    ) -> tuple[NDArray[np.float32], NDArray[np.int64]]: ...
    @overload
    def nearest(
        self,
        points: ArrayLike,
        k: int,
        *,
        distance_upper_bound: float = ...,
        metric: Metric = "surface",
        filter: QueryFilter = None,
        workers: int = 1,
    ) -> tuple[NDArray[np.float32], NDArray[np.int64]]:
        """The ``k`` objects nearest to each point, like scipy's
        ``cKDTree.query``: ``points`` (M, 3) (or one (3,) point) →
        ``(distances, ids)``, nearest first, ties by smaller id.

        Shapes follow cKDTree: (M, k) for k > 1, (M,) for k == 1, and without
        the M axis for a single (3,) point (a float and an int for k == 1).
        Rows with fewer than k qualifying objects are padded with distance inf
        and id -1 (cKDTree pads with inf and n; -1 is never an id). Distances
        are float32, ids int64.

        ``metric``: "surface" (default; max(0, |c - p| - r), 0 inside a
        sphere) or "center" (|c - p|, as cKDTree for points; equal for radius
        0). ``distance_upper_bound``: only objects at most this far
        (inclusive; cKDTree's is strict). ``filter``: as for
        :meth:`query_spheres`. Each distance is correctly rounded, so every
        kind gives the same answer bit for bit. Releases the GIL.

        Raises ValueError on a wrong shape, a non-finite point, k < 1, a NaN
        or negative bound or an unknown metric; TypeError on a non-integer k;
        MemoryError when the (M, k) answer cannot be allocated (a huge k).
        """

    @overload
    def sweep(
        self,
        starts: ArrayLike,
        ends: ArrayLike,
        radii: ArrayLike | float | None = None,
        *,
        all: Literal[False] = False,
        filter: QueryFilter = None,
        workers: int = 1,
    ) -> tuple[NDArray[np.int64], NDArray[np.float32]]: ...
    @overload
    def sweep(
        self,
        starts: ArrayLike,
        ends: ArrayLike,
        radii: ArrayLike | float | None = None,
        *,
        all: Literal[True],
        filter: QueryFilter = None,
        workers: int = 1,
    ) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.float32]]:
        """Sphere casts: a sphere of radius ``radii[i]`` (scalar or (M,), >= 0;
        default 0, the exact segment query) whose centre moves in a straight
        line from ``starts[i]`` (t = 0) to ``ends[i]`` (t = 1), both (M, 3).
        It touches a stored sphere when their distance comes to at most the
        sum of the radii (closed).

        Returns the first object each sweep touches, ``(ids (M,), t (M,))`` —
        smallest time of impact, ties by smaller id, -1 and inf for a miss, t
        = 0 when touching at the start — or with ``all=True`` every object
        touched as ``(ids, offsets, t)``, each sweep's in order of t, ties by
        id. ``filter`` as for :meth:`query_spheres`. Releases the GIL."""

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
        ValueError, changing nothing, on a wrong count or a non-finite vertex,
        or while the mesh is the shape of objects of a :class:`World`."""

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

class WorldRayCastResult(TypedDict):
    """The answer of :meth:`World.ray_cast` (Open3D's names)."""

    t_hit: NDArray[np.float32]
    """(R,) hit parameter, inf for a miss."""
    geometry_ids: NDArray[np.int64]
    """(R,) the object hit (its id), -1 for a miss."""
    primitive_ids: NDArray[np.int64]
    """(R,) the triangle hit (0 for a ball), -1 for a miss."""

class WorldCounters(TypedDict):
    """What one :meth:`World.contacts` query did."""

    broad_pairs: int
    """Candidate object pairs from the broad phase."""
    filtered: int
    """Candidates dropped by the filters or as ignored pairs."""
    narrow_pairs: int
    """Pairs the narrow phase tested."""
    coherent_pairs: int
    """Pairs of unchanged objects whose last answer was reused."""
    cut_starts: int
    """Tests that started from the pair's last traversal cut."""
    nv: int
    """Bounding-volume pair tests."""
    np: int
    """Primitive pair tests."""
    nu: int
    """Bounding-volume updates."""

class WorldContacts:
    """The answer of :meth:`World.contacts`: P object pairs in contact.
    ``len(contacts)`` is P, ``contacts[i]`` the (K_i, 2) primitive pairs of
    pair i, ``bool(contacts)`` whether any pair touches."""

    @property
    def pairs(self) -> NDArray[np.int64]:
        """(P, 2) object ids (a, b), a < b, rows sorted."""

    @property
    def offsets(self) -> NDArray[np.int64]:
        """(P + 1,): pair i's primitive pairs are
        ``triangles[offsets[i]:offsets[i+1]]``."""

    @property
    def triangles(self) -> NDArray[np.int64]:
        """(K, 2) primitive pairs (triangle of a, triangle of b; 0 for a
        ball), ascending within each pair; one per pair with ``first=True``."""

    @property
    def counters(self) -> WorldCounters:
        """What the query did."""

    def __len__(self) -> int: ...
    def __bool__(self) -> bool: ...
    def __getitem__(self, i: int) -> NDArray[np.int64]: ...

class World:
    """A collision world: objects, each a shape -- a shared :class:`Mesh` or a
    solid ball -- at a rigid pose with collision filter bits, in a broad-phase
    index, with exact mesh-mesh, mesh-ball and ball-ball tests.

    Objects are named by integer **ids**: insertion order, never reused
    (a removed id raises ``KeyError``). Poses are (4, 4) or (3, 4) row-major
    ``[R | t]`` rigid motions (|RᵀR - I| <= 1e-3, det > 0, finite); anything
    else raises ``ValueError`` and changes nothing. Two objects are tested only
    if ``group_a & mask_b`` and ``group_b & mask_a`` are both non-zero and the
    pair is not ignored. Meshes are surfaces (a mesh wholly inside another
    does not touch it); balls are solid. ``workers``: 1 (this thread), n (a
    pool of n threads) or -1 (one per core).
    """

    def __init__(
        self,
        *,
        index: IndexKind | None = None,
        bv: BoundingVolume = "kdop18",
        bounds: ArrayLike | None = None,
        coherence: bool = True,
        rotation: Literal["auto", "refit", "conservative"] = "auto",
    ) -> None:
        """An empty world. ``index``: the broad-phase kind (None: "loose-kd").
        ``bv``: the bounding volume of the meshes it takes. ``bounds`` ([min,
        max], (2, 3) or (6,)): where the objects will be (None: the index is
        built at the first query and rebuilt when the scene drifts).
        ``coherence``: skip pairs unchanged since the last contacts (same
        answers). ValueError on an unknown name or a bad box."""

    @property
    def index(self) -> str:
        """The broad-phase index kind."""

    @property
    def bv(self) -> str:
        """The bounding volume of the world's meshes."""

    @property
    def n_ignored(self) -> int:
        """Number of ignored pairs."""

    @property
    def memory_bytes(self) -> int:
        """Heap bytes of the world's own structures (shared meshes not counted)."""

    def __len__(self) -> int: ...
    def __contains__(self, id: object) -> bool: ...
    def ids(self) -> NDArray[np.int64]:
        """The ids of the objects, ascending."""

    def add(
        self,
        shape: Mesh | float,
        pose: ArrayLike | None = None,
        *,
        group: int = 0xFFFFFFFF,
        mask: int = 0xFFFFFFFF,
    ) -> int:
        """Adds an object and returns its id. ``shape``: a :class:`Mesh`
        (shared, not copied) or a ball radius. ``pose``: None (identity),
        (4, 4) or (3, 4). ValueError, adding nothing, on a bad pose or radius,
        or a mesh whose bv is not the world's; TypeError on another shape."""

    def add_many(
        self,
        shape: Mesh | float,
        poses: ArrayLike,
        *,
        group: int = 0xFFFFFFFF,
        mask: int = 0xFFFFFFFF,
    ) -> NDArray[np.int64]:
        """One object per pose of ``poses`` ((N, 4, 4) or (N, 3, 4)), all
        sharing ``shape``; returns their ids (N,). All or nothing."""

    def remove(self, id: int) -> None:
        """Removes an object and its ignored pairs. KeyError if absent."""

    def remove_many(self, ids: ArrayLike) -> None:
        """Removes every object of ``ids``. All or nothing: KeyError if one is
        absent or appears twice."""

    def set_pose(self, id: int, pose: ArrayLike) -> None:
        """Moves one object. KeyError / ValueError, changing nothing."""

    def set_poses(self, ids: ArrayLike, poses: ArrayLike) -> None:
        """Moves objects ``ids`` (N,) to ``poses`` ((N, 4, 4) or (N, 3, 4));
        an id listed twice takes its last pose. All or nothing."""

    def pose(self, id: int) -> NDArray[np.float32]:
        """An object's pose, (4, 4)."""

    def set_filter(self, id: int, *, group: int, mask: int) -> None:
        """Sets an object's filter bits (each in 0..2**32)."""

    def filter(self, id: int) -> tuple[int, int]:
        """An object's filter as (group, mask)."""

    def ignore(self, a: int, b: int) -> None:
        """Never report the pair (a, b) in contacts (an allowed-collision
        matrix entry). KeyError for an absent id; ValueError for a == b."""

    def unignore(self, a: int, b: int) -> bool:
        """Reports (a, b) again; returns whether it was ignored."""

    def is_ignored(self, a: int, b: int) -> bool:
        """Whether the pair (a, b) is ignored."""

    def contacts(self, *, first: bool = False, workers: int = 1) -> WorldContacts:
        """Every pair of objects whose posed shapes share a point (touching
        counts), each once, after filters and ignored pairs, with all its
        intersecting primitive pairs (one witness with ``first=True``).
        Releases the GIL."""

    def ray_cast(
        self,
        rays: ArrayLike,
        tmax: ArrayLike | float | None = None,
        *,
        group: int = 0xFFFFFFFF,
        mask: int = 0xFFFFFFFF,
        workers: int = 1,
    ) -> WorldRayCastResult:
        """The first primitive each ray ((R, 6): origin, direction) hits for
        t in [0, tmax], among objects whose filter meets (group, mask):
        smallest t, ties to the smaller id, then triangle. Balls are solid."""

    def overlap_sphere(
        self,
        spheres: ArrayLike,
        *,
        group: int = 0xFFFFFFFF,
        mask: int = 0xFFFFFFFF,
        workers: int = 1,
    ) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """Objects with some point within r of each query ((M, 4): x, y, z,
        r), exactly: ``(ids, offsets)``, each query's ids ascending."""

    def cull(
        self,
        matrices: ArrayLike,
        *,
        depth: Literal["zero_to_one", "minus_one_to_one"] = "zero_to_one",
        group: int = 0xFFFFFFFF,
        mask: int = 0xFFFFFFFF,
        workers: int = 1,
    ) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """Objects whose bounding sphere is not entirely outside each view
        frustum ((M, 4, 4) view-projection matrices): ``(ids, offsets)``."""

    def validate(self) -> None:
        """Checks the invariants (RuntimeError if one fails: a bug)."""
