"""Proxima: spatial queries and collision detection for dynamic 3D scenes.

- :class:`Index` -- any of the six broad-phase indices ("brute", "loose-kd",
  "octree", "grid2d", "hashgrid", "grid3d") over bounding spheres, built from
  numpy arrays; batch sphere/box/ray/frustum queries returning ``(ids,
  offsets)``; all overlapping pairs as an ``(P, 2)`` array.
- :class:`Mesh` -- a triangle mesh (arrays or an OBJ/STL/PLY file) with its
  collision BVH and ray BVH; :meth:`Mesh.cast_rays` returns Open3D's
  ``t_hit`` / ``primitive_ids`` / ``primitive_uvs``.
- :func:`collide` -- exact mesh-mesh collision for one pose or a batch of
  poses, returning :class:`Contacts` (triangle pairs and cost counters).
- :class:`World` -- the collision world: shared meshes and balls at rigid
  poses with filter bits and ignored pairs; :meth:`World.contacts` (object
  pairs and their triangle pairs, :class:`WorldContacts`), ray casts, sphere
  queries, culling.

Bad input raises ``ValueError`` (``KeyError`` for an id not in an index or world,
``FileNotFoundError`` / ``OSError`` for unreadable files) with the library's
message. Long calls release the GIL; batch calls take ``workers=`` (1: this
thread, n: a pool of n threads, -1: one per core).
"""

from importlib.metadata import PackageNotFoundError, version

from ._native import (
    BOUNDING_VOLUMES,
    INDEX_KINDS,
    Contacts,
    Index,
    Mesh,
    World,
    WorldContacts,
    collide,
)

try:
    __version__ = version("proxima")
except PackageNotFoundError:  # pragma: no cover - run from a source tree
    __version__ = "0.0.0"

__all__ = [
    "BOUNDING_VOLUMES",
    "INDEX_KINDS",
    "Contacts",
    "Index",
    "Mesh",
    "World",
    "WorldContacts",
    "collide",
]
