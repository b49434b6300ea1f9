//! The collision world: shared shapes, posed objects, a broad phase and the
//! narrow phase as one system [sources: world].
//!
//! A [`World`] holds objects, each a [`Shape`] (a shared mesh with its trees, or a
//! ball) at a rigid pose (`glam::Affine3A`), with a payload `T` and a collision
//! [`Filter`], named by a generational [`Handle`]. Its queries:
//!
//! - [`World::contacts`] / [`World::contacts_first`]: every pair of objects whose
//!   posed shapes share a point, with their intersecting triangle pairs (or one
//!   witness), after filters and ignored pairs (`contacts.rs`, the per-pair test
//!   in `pair.rs`, temporal coherence in `coherence.rs`, the parallel form in
//!   `par.rs`);
//! - [`World::ray_cast`] / [`World::ray_hits`]: the first triangle a ray hits,
//!   and every object it hits (`ray.rs`);
//! - [`World::overlap_sphere`], [`World::cull`]: objects near a point, objects in
//!   a view frustum (`region.rs`);
//! - [`World::distance`], [`World::nearest_obstacle`], [`World::contacts_within`]:
//!   how far apart two objects are, the nearest obstacle of one, contacts with a
//!   margin (`distance.rs`).
//!
//! The broad phase (`broad.rs`) is an [`AnyIndex`](crate::broad::AnyIndex) chosen
//! at run time ([`WorldConfig::index`]) over each object's bounding sphere; the
//! allowed-collision matrix is in `ignore.rs`, the invariants in `validate.rs`.
//!
//! ```
//! use proxima::glam::{Affine3A, Vec3};
//! use proxima::narrow::Mesh;
//! use proxima::world::{Shape, World, WorldConfig};
//!
//! // A unit tetrahedron, shared by two objects.
//! let v = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
//! let t = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
//! let tet: Shape = Mesh::new(v, t).unwrap().into();
//! let mut world = World::new(WorldConfig::default()).unwrap();
//! let a = world.insert(tet.clone(), Affine3A::IDENTITY, "a").unwrap();
//! let b = world.insert(tet, Affine3A::from_translation(Vec3::splat(0.2)), "b").unwrap();
//! let report = world.contacts().unwrap();
//! assert_eq!(report.pairs.len(), 1);
//! assert_eq!((report.pairs[0].a, report.pairs[0].b), (a, b));
//! assert!(!report.triangles_of(&report.pairs[0]).is_empty());
//! // Far apart: no contact.
//! world.set_pose(b, Affine3A::from_translation(Vec3::splat(5.0))).unwrap();
//! assert!(world.contacts().unwrap().pairs.is_empty());
//! ```

mod broad;
mod coherence;
mod contacts;
mod distance;
mod ignore;
mod pair;
#[cfg(feature = "parallel")]
mod par;
mod ray;
mod region;
mod shape;
mod validate;

pub use contacts::{ContactMode, ContactReport, ObjectContact, WorldCounters};
pub use distance::ObjectDistance;
pub use ray::WorldRayHit;
pub use shape::Shape;

use crate::arena::Arena;
use crate::broad::{Filter, IndexKind};
use crate::geom::{Aabb, Sphere};
use crate::narrow::{BoundingVolume, Kdop18, RotationUpdate};
use crate::{Error, Handle, Result};
use broad::Broad;
use coherence::Coherence;
use glam::{Affine3A, Vec3};
use ignore::IgnoredPairs;
use pair::PairScratch;

/// How a [`World`] is built. `WorldConfig::default()` fits most scenes; set
/// only what you know.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldConfig {
    /// The broad-phase index. `None` (the default): [`IndexKind::LooseKd`], the
    /// index whose cost depends least on the scene's sizes and spread
    /// ([`broad::LooseKdTree`](crate::broad::LooseKdTree): mixed sizes and
    /// drifting scenes do not degrade it, unlike the grids).
    pub index: Option<IndexKind>,
    /// Where the objects' centres will be. `None` (the default): the index is
    /// built at the first query from the objects present then
    /// ([`SceneHint::from_spheres`](crate::broad::SceneHint::from_spheres)), and
    /// rebuilt when the scene drifts far from it (see [`World`]). `Some(box)`:
    /// the index covers that box for its whole life (objects outside it are
    /// still handled exactly, only slower).
    pub bounds: Option<Aabb>,
    /// How axis-aligned bounding volumes follow rotated poses in mesh–mesh tests.
    pub rotation: RotationUpdate,
    /// Temporal coherence (the default: on): pairs of objects that did not change
    /// since the last `contacts` are not tested again, and, with a
    /// `cut_limit` above 0, the other pairs start from where their last
    /// traversal ended. Answers are the same either way.
    pub coherence: bool,
    /// The largest traversal cut (node pairs) kept per object pair for
    /// coherence; larger ones are dropped and the next test starts from the
    /// roots. Default 0: no cuts, the fastest on every bench scene (motions of
    /// a few hundredths of an object's size per frame cost 1–24% more
    /// instructions with 1024); cuts pay only for much smaller motions (see
    /// `coherence.rs`).
    pub cut_limit: usize,
}

impl Default for WorldConfig {
    fn default() -> Self {
        WorldConfig {
            index: None,
            bounds: None,
            rotation: RotationUpdate::Auto,
            coherence: true,
            cut_limit: coherence::DEFAULT_CUT_LIMIT,
        }
    }
}

/// One object of the world.
#[derive(Clone, Debug)]
pub(crate) struct Object<T, BV> {
    pub(crate) shape: Shape<BV>,
    pub(crate) pose: Affine3A,
    /// `pose.inverse()`, kept for relative poses, rays and spheres.
    pub(crate) inverse: Affine3A,
    /// The broad phase's sphere ([`broad_sphere`]).
    pub(crate) sphere: Sphere,
    pub(crate) filter: Filter,
    pub(crate) value: T,
    /// The handle in the broad-phase index, once it is built.
    pub(crate) broad: Option<Handle>,
    /// The world's epoch at the object's last change (coherence).
    pub(crate) stamp: u64,
    /// Insertion number, unique over the world's life: decides which mesh of a
    /// pair moves when both have as many triangles.
    pub(crate) seq: u64,
    /// Whether the sphere lies far from the index's scene hint (`broad.rs`).
    pub(crate) drift: bool,
}

/// A read-only view of one object ([`World::object`], [`World::iter`]).
#[derive(Debug)]
pub struct ObjectRef<'a, T, BV = Kdop18> {
    /// The object's handle.
    pub handle: Handle,
    /// Its shape.
    pub shape: &'a Shape<BV>,
    /// Its pose (object frame to world frame).
    pub pose: &'a Affine3A,
    /// Its collision filter.
    pub filter: Filter,
    /// Its payload.
    pub value: &'a T,
    /// The sphere the broad phase holds for it: the shape's bounding sphere
    /// moved by the pose, grown by a small margin that covers rounding and the
    /// pose's allowed deviation from a rotation.
    pub bounding_sphere: Sphere,
}

/// A collision world of objects, each a shared [`Shape`] at a rigid pose with a
/// payload `T` and a [`Filter`], over a broad-phase index chosen at run time and
/// the mesh trees of the narrow phase ([sources: world]). `BV` is the collision
/// trees' bounding volume (every mesh shape of one world uses the same kind).
///
/// **Objects.** [`World::insert`] / [`World::insert_with_filter`] → a
/// generational [`Handle`]; [`World::set_pose`] is the per-frame call
/// ([`World::set_poses`] for a batch, all checked first); [`World::remove`],
/// [`World::get`], [`World::get_mut`], [`World::set_filter`], [`World::len`],
/// [`World::iter`]. Poses are `glam::Affine3A` rigid motions: a matrix that is
/// not a rotation (as [`check_pose`](crate::narrow::check_pose) decides: `RᵀR`
/// within `1e-3` of the identity, determinant positive) or a non-finite entry is
/// [`Error::InvalidPose`]; a stale handle is [`Error::StaleHandle`]; every
/// failing call leaves the world exactly as it was.
///
/// **Ignored pairs** (the allowed-collision matrix of robotics: adjacent links
/// always touch): [`World::ignore`], [`World::unignore`], [`World::is_ignored`].
/// Removing an object drops its ignored pairs.
///
/// **Broad phase.** The index holds each object's bounding sphere (a mesh's
/// sphere about a point fixed in the mesh, so a pose change only moves it). With
/// [`WorldConfig::bounds`] unset, it is built at the first query from the objects
/// present (before that, queries that take `&self` scan the objects), and
/// rebuilt, O(n), before a `contacts` query or [`World::update_broad_phase`]
/// when the scene has drifted far from what it was built for: when more than
/// `max(8, n/4)` of the `n` objects have a centre outside the built world box
/// grown by half its extent, or a radius above 4× the built `r_max`. Each
/// rebuild needs that many changes first, so its cost is O(1) amortized per
/// change. Queries that take `&self` never rebuild; they stay exact.
///
/// **Meshes in contact.** For a mesh pair, the mesh with more triangles (on a
/// tie, the object inserted later) is moved into the frame of the other by the
/// relative pose `pose_fixed⁻¹ · pose_moving`, and its triangles, transformed in
/// `f32`, are tested exactly against the other's ([`Collider`]). That is the
/// definition the answers are exact for (a brute-force oracle uses the same
/// frames). A ball is tested in the mesh's frame against every triangle
/// ([`sphere_triangle`](crate::narrow::sphere_triangle)), two balls in the world
/// frame.
///
/// [`Collider`]: crate::narrow::Collider
#[derive(Debug)]
pub struct World<T, BV: BoundingVolume = Kdop18> {
    config: WorldConfig,
    objects: Arena<Object<T, BV>>,
    broad: Broad,
    ignored: IgnoredPairs,
    coherence: Coherence,
    /// Advanced after each `contacts`; stamps changes for coherence.
    epoch: u64,
    next_seq: u64,
    scratch: PairScratch<BV>,
}

impl<T, BV: BoundingVolume> World<T, BV> {
    /// An empty world. Fails with [`Error::InvalidParameter`] on a
    /// [`WorldConfig::bounds`] box that is inverted or not finite, or on a
    /// `cut_limit` above 2^20. O(1).
    pub fn new(config: WorldConfig) -> Result<World<T, BV>> {
        if let Some(b) = config.bounds {
            b.validate()
                .map_err(|e| Error::InvalidParameter(format!("world bounds: {e}")))?;
        }
        if config.cut_limit > coherence::MAX_CUT_LIMIT {
            return Err(Error::InvalidParameter(format!(
                "cut_limit {} is above {}",
                config.cut_limit,
                coherence::MAX_CUT_LIMIT
            )));
        }
        Ok(World {
            config,
            objects: Arena::new(),
            broad: Broad::default(),
            ignored: IgnoredPairs::default(),
            coherence: Coherence::default(),
            epoch: 1,
            next_seq: 0,
            scratch: PairScratch::new(config.rotation),
        })
    }

    /// The configuration the world was built with.
    pub fn config(&self) -> &WorldConfig {
        &self.config
    }

    /// Adds an object with the default filter ([`Filter::ALL`]); see
    /// [`World::insert_with_filter`].
    pub fn insert(&mut self, shape: Shape<BV>, pose: Affine3A, value: T) -> Result<Handle> {
        self.insert_with_filter(shape, pose, value, Filter::ALL)
    }

    /// Adds an object: `shape` at `pose` with payload `value` and collision
    /// `filter`. O(1) plus one index insert once the index is built.
    ///
    /// Fails, adding nothing, with [`Error::InvalidPose`] on a pose that is not
    /// a rigid motion or that moves the shape's bounding sphere beyond
    /// [`COORDINATE_LIMIT`], a radius error
    /// for a `Shape::Sphere` with a negative or non-finite radius, or
    /// [`Error::CapacityExceeded`].
    pub fn insert_with_filter(
        &mut self,
        shape: Shape<BV>,
        pose: Affine3A,
        value: T,
        filter: Filter,
    ) -> Result<Handle> {
        shape.validate()?;
        let posed = Posed::new(&shape, &pose)?;
        self.objects.check_room()?;
        let slot = self.objects.next_handle().index();
        let broad = self.broad.insert(posed.sphere, filter, slot)?;
        let drift = self
            .broad
            .is_drifted(&posed.sphere, self.config.bounds.is_some());
        let object = Object {
            shape,
            pose,
            inverse: posed.inverse,
            sphere: posed.sphere,
            filter,
            value,
            broad,
            stamp: self.epoch,
            seq: self.next_seq,
            drift,
        };
        let h = self
            .objects
            .insert(object)
            .expect("room was checked before the index changed");
        self.next_seq += 1;
        self.broad.drifted += drift as usize;
        Ok(h)
    }

    /// Removes an object and returns its payload; its ignored pairs are
    /// dropped. O(1) plus one index removal and O(k) for its k ignored pairs.
    /// Fails with [`Error::StaleHandle`], changing nothing.
    pub fn remove(&mut self, handle: Handle) -> Result<T> {
        let o = self.objects.get(handle)?;
        if let Some(b) = o.broad {
            self.broad.remove(b)?;
        }
        self.broad.drifted -= o.drift as usize;
        self.ignored.drop_object(handle.index());
        let o = self.objects.remove(handle)?;
        Ok(o.value)
    }

    /// Moves an object: its new pose. O(1) plus one index update. A pose equal
    /// to the current one (bit for bit) changes nothing, so coherence still
    /// skips the object's pairs.
    ///
    /// Fails, changing nothing, with [`Error::StaleHandle`] or
    /// [`Error::InvalidPose`] (not a rigid motion, non-finite, or moving the
    /// shape beyond [`COORDINATE_LIMIT`]).
    pub fn set_pose(&mut self, handle: Handle, pose: Affine3A) -> Result<()> {
        let o = self.objects.get(handle)?;
        if o.pose == pose {
            return Ok(());
        }
        let posed = Posed::new(&o.shape, &pose)?;
        self.apply_pose(handle, pose, posed);
        Ok(())
    }

    /// Moves several objects (a frame's motion): every handle and pose is
    /// checked first, then all are applied, so on error nothing changed. A
    /// handle listed twice takes its last pose. O(k) plus k index updates.
    pub fn set_poses(&mut self, poses: &[(Handle, Affine3A)]) -> Result<()> {
        let mut checked = Vec::with_capacity(poses.len());
        for (h, pose) in poses {
            let o = self.objects.get(*h)?;
            checked.push(Posed::new(&o.shape, pose)?);
        }
        for ((h, pose), posed) in poses.iter().zip(checked) {
            if self.objects.get(*h)?.pose != *pose {
                self.apply_pose(*h, *pose, posed);
            }
        }
        Ok(())
    }

    /// Stores a checked pose and moves the object's sphere in the index.
    fn apply_pose(&mut self, handle: Handle, pose: Affine3A, posed: Posed) {
        let bounded = self.config.bounds.is_some();
        let drift = self.broad.is_drifted(&posed.sphere, bounded);
        let epoch = self.epoch;
        let o = self
            .objects
            .get_mut(handle)
            .expect("the handle was checked");
        if let Some(b) = o.broad {
            self.broad
                .update(b, posed.sphere)
                .expect("a live object's index handle and a checked sphere");
        }
        self.broad.drifted = self.broad.drifted - o.drift as usize + drift as usize;
        o.pose = pose;
        o.inverse = posed.inverse;
        o.sphere = posed.sphere;
        o.drift = drift;
        o.stamp = epoch;
    }

    /// Sets an object's collision filter. O(1). Fails with
    /// [`Error::StaleHandle`].
    pub fn set_filter(&mut self, handle: Handle, filter: Filter) -> Result<()> {
        let epoch = self.epoch;
        let o = self.objects.get_mut(handle)?;
        if o.filter != filter {
            o.filter = filter;
            o.stamp = epoch;
            if let Some(b) = o.broad {
                self.broad.set_filter(b, filter)?;
            }
        }
        Ok(())
    }

    /// The payload of an object. Fails with [`Error::StaleHandle`].
    pub fn get(&self, handle: Handle) -> Result<&T> {
        Ok(&self.objects.get(handle)?.value)
    }

    /// The payload of an object, mutably. Fails with [`Error::StaleHandle`].
    pub fn get_mut(&mut self, handle: Handle) -> Result<&mut T> {
        Ok(&mut self.objects.get_mut(handle)?.value)
    }

    /// Everything about one object. Fails with [`Error::StaleHandle`].
    pub fn object(&self, handle: Handle) -> Result<ObjectRef<'_, T, BV>> {
        Ok(view(handle, self.objects.get(handle)?))
    }

    /// An object's pose. Fails with [`Error::StaleHandle`].
    pub fn pose(&self, handle: Handle) -> Result<Affine3A> {
        Ok(self.objects.get(handle)?.pose)
    }

    /// Whether `handle` names a live object of this world.
    pub fn contains(&self, handle: Handle) -> bool {
        self.objects.contains(handle)
    }

    /// Number of objects.
    pub fn len(&self) -> usize {
        self.objects.len()
    }

    /// True when the world holds no object.
    pub fn is_empty(&self) -> bool {
        self.objects.is_empty()
    }

    /// Every object, in handle order.
    pub fn iter(&self) -> impl Iterator<Item = ObjectRef<'_, T, BV>> + '_ {
        self.objects.iter().map(|(h, o)| view(h, o))
    }

    /// Never report the pair `(a, b)` (either order) in contacts: an entry of
    /// the allowed-collision matrix. O(1). Fails with [`Error::StaleHandle`], or
    /// [`Error::InvalidParameter`] for `a == b`.
    pub fn ignore(&mut self, a: Handle, b: Handle) -> Result<()> {
        self.check_pair(a, b)?;
        if self.ignored.insert(a.index(), b.index()) {
            self.touch(a);
            self.touch(b);
        }
        Ok(())
    }

    /// Reports the pair `(a, b)` again; returns whether it was ignored. O(1).
    /// Fails as [`World::ignore`] does.
    pub fn unignore(&mut self, a: Handle, b: Handle) -> Result<bool> {
        self.check_pair(a, b)?;
        let was = self.ignored.remove(a.index(), b.index());
        if was {
            self.touch(a);
            self.touch(b);
        }
        Ok(was)
    }

    /// Whether the pair `(a, b)` is ignored. O(1). Fails as [`World::ignore`]
    /// does.
    pub fn is_ignored(&self, a: Handle, b: Handle) -> Result<bool> {
        self.check_pair(a, b)?;
        Ok(self.ignored.contains(a.index(), b.index()))
    }

    /// Number of ignored pairs.
    pub fn ignored_len(&self) -> usize {
        self.ignored.len()
    }

    fn check_pair(&self, a: Handle, b: Handle) -> Result<()> {
        self.objects.get(a)?;
        self.objects.get(b)?;
        if a == b {
            return Err(Error::InvalidParameter(
                "a pair needs two different objects".into(),
            ));
        }
        Ok(())
    }

    /// Marks an object changed for coherence (its pairs' filtering changed).
    fn touch(&mut self, h: Handle) {
        let epoch = self.epoch;
        if let Ok(o) = self.objects.get_mut(h) {
            o.stamp = epoch;
        }
    }

    /// Builds the broad-phase index if it is not built yet, or rebuilds it if
    /// the scene has drifted far from it (the rule is in [`World`]'s docs);
    /// `contacts` calls it. O(1) when nothing is due, O(n) for a build.
    /// Answers never depend on it. Fails only if the index cannot be built for
    /// the scene (an [`Error::InvalidParameter`] from its config).
    pub fn update_broad_phase(&mut self) -> Result<()> {
        if self.broad.due(self.objects.len()) {
            self.broad.rebuild(&self.config, &mut self.objects)?;
        }
        Ok(())
    }

    /// The broad-phase index kind in use, once built.
    pub fn index_kind(&self) -> Option<IndexKind> {
        self.broad.kind()
    }

    /// Number of times the broad-phase index was built (the first build
    /// included).
    pub fn broad_phase_builds(&self) -> u64 {
        self.broad.builds
    }

    /// Heap bytes held by the world's own structures (objects, index, ignored
    /// pairs, coherence cache, scratch space); shapes are shared and not
    /// counted. O(1) to O(index).
    pub fn memory_bytes(&self) -> usize {
        self.objects.heap_bytes()
            + self.broad.memory_bytes()
            + self.ignored.memory_bytes()
            + self.coherence.memory_bytes()
    }
}

fn view<T, BV>(handle: Handle, o: &Object<T, BV>) -> ObjectRef<'_, T, BV> {
    ObjectRef {
        handle,
        shape: &o.shape,
        pose: &o.pose,
        filter: o.filter,
        value: &o.value,
        bounding_sphere: o.sphere,
    }
}

/// What a pose implies for an object: checked, inverted, its broad sphere.
#[derive(Clone, Copy, Debug)]
struct Posed {
    inverse: Affine3A,
    sphere: Sphere,
}

impl Posed {
    /// Checks `pose` ([`check_pose`](crate::narrow::check_pose)) and computes
    /// its inverse and the shape's broad sphere; fails with
    /// [`Error::InvalidPose`] if the sphere reaches beyond [`COORDINATE_LIMIT`].
    fn new<BV: BoundingVolume>(shape: &Shape<BV>, pose: &Affine3A) -> Result<Posed> {
        crate::narrow::check_pose(pose)?;
        let inverse = pose.inverse();
        let sphere = broad_sphere(&shape.local_bounding_sphere(), pose);
        let reach = sphere.center.abs().max_element() + sphere.radius;
        // NaN fails too.
        if !inverse.is_finite() || !reach.is_finite() || reach > COORDINATE_LIMIT {
            return Err(Error::InvalidPose(format!(
                "pose moves the shape beyond ±{COORDINATE_LIMIT:e} (to {reach:e})"
            )));
        }
        Ok(Posed { inverse, sphere })
    }
}

/// The largest coordinate a posed shape may reach: relative poses, slacks and
/// index boxes computed from such coordinates stay far inside `f32` range.
pub const COORDINATE_LIMIT: f32 = 1e30;

/// Relative growth of broad-phase radii: covers the scaling by up to
/// `1 + 1.5 · 1e-3` of a matrix that deviates from a rotation by the allowed
/// `1e-3` (distances measured in another object's frame), twice over.
const RADIUS_GROWTH: f32 = 4e-3;

/// Absolute growth of broad-phase radii, relative to the magnitudes involved:
/// far above the rounding of `f32` pose transforms (about 1e-7 of them).
const ROUNDING_GROWTH: f32 = 1e-5;

/// The broad phase's sphere for a shape whose local bounding sphere is `local`
/// at `pose`: the centre moved by the pose, the radius grown so that the
/// sphere contains the shape however the narrow phase transforms it (by this
/// pose, by a relative pose into another object's frame, rounded in `f32`).
pub(crate) fn broad_sphere(local: &Sphere, pose: &Affine3A) -> Sphere {
    let center = pose.transform_point3(local.center);
    let t = Vec3::from(pose.translation);
    let magnitude = local.center.abs().max_element() + t.abs().max_element() + local.radius;
    Sphere::new(center, grown_radius(local.radius, magnitude))
}

/// `radius` grown by [`RADIUS_GROWTH`] and [`ROUNDING_GROWTH`] of `magnitude`,
/// rounded up.
pub(crate) fn grown_radius(radius: f32, magnitude: f32) -> f32 {
    let r = radius * (1.0 + RADIUS_GROWTH) + ROUNDING_GROWTH * magnitude;
    if r.is_finite() {
        f32::from_bits(r.to_bits() + 1)
    } else {
        r
    }
}
