// W5 peer harness: mesh vs mesh with FCL 0.7 (-DPEER_FCL) or coal 3.0
// (-DPEER_COAL); README.md beside this file.
//
//   w5_mesh --lib fcl|coal [--bv obbrss|obb|rss|kdop18|aabb] A B POSES
//           [--mode all|first|distance] [--reps N] [--path direct|api]
//
// Builds one BVH per mesh (the library's default build), then per pose of POSES
// (design §4.2: moves A, B at the identity) prints the answer in the line format
// of `proxima collide` (`pairs N`, `hit 0|1`; `distance D I J` as planned for
// issue 15), then `#` lines with the build and query times.
#include "common.hpp"

#include <limits>
#include <memory>

#if defined(PEER_FCL)
#include <fcl/config.h>
#include <fcl/fcl.h>
#include <fcl/narrowphase/detail/traversal/collision_node.h>
#include <fcl/narrowphase/detail/traversal/collision/mesh_collision_traversal_node.h>
#include <fcl/narrowphase/detail/traversal/distance/mesh_distance_traversal_node.h>
#define LIB_NAME "fcl"
#define LIB_VERSION FCL_VERSION
namespace L = fcl;
using Vec3 = fcl::Vector3d;
using Transform = fcl::Transform3d;
using Tri = fcl::Triangle;
using CollisionRequest = fcl::CollisionRequestd;
using CollisionResult = fcl::CollisionResultd;
using DistanceRequest = fcl::DistanceRequestd;
using DistanceResult = fcl::DistanceResultd;
using BvObbrss = fcl::OBBRSSd;
using BvObb = fcl::OBBd;
using BvRss = fcl::RSSd;
using BvKdop18 = fcl::KDOPd<18>;
using BvAabb = fcl::AABBd;
#elif defined(PEER_COAL)
#include <coal/BVH/BVH_model.h>
#include <coal/collision.h>
#include <coal/config.hh>
#include <coal/distance.h>
#define LIB_NAME "coal"
#define LIB_VERSION COAL_VERSION
namespace L = coal;
using Vec3 = coal::Vec3s;
using Transform = coal::Transform3s;
using Tri = coal::Triangle;
using CollisionRequest = coal::CollisionRequest;
using CollisionResult = coal::CollisionResult;
using DistanceRequest = coal::DistanceRequest;
using DistanceResult = coal::DistanceResult;
using BvObbrss = coal::OBBRSS;
using BvObb = coal::OBB;
using BvRss = coal::RSS;
using BvKdop18 = coal::KDOP<18>;
using BvAabb = coal::AABB;
#else
#error "build with -DPEER_FCL or -DPEER_COAL (scripts/peers.sh)"
#endif

using peers::die;

namespace {

enum class Mode { All, First, Distance };

struct Options {
    std::string bv = "obbrss";
    Mode mode = Mode::All;
    long reps = 1;
    bool direct = true;
};

Transform to_transform(const peers::Pose& p) {
    Eigen::Matrix3d r;
    r << p.r[0], p.r[1], p.r[2], p.r[3], p.r[4], p.r[5], p.r[6], p.r[7], p.r[8];
    Vec3 t(p.t[0], p.t[1], p.t[2]);
#if defined(PEER_FCL)
    Transform tf = Transform::Identity();
    tf.linear() = r;
    tf.translation() = t;
    return tf;
#else
    return Transform(r, t);
#endif
}

Transform identity() {
#if defined(PEER_FCL)
    return Transform::Identity();
#else
    return Transform::Identity();
#endif
}

// The library's BVH over a mesh, built with its defaults (beginModel,
// addSubModel, endModel); returns the build time in ns through `ns`.
template <class BV>
std::shared_ptr<L::BVHModel<BV>> build(const peers::Mesh& m, double& ns) {
    std::vector<Vec3> v(m.vertices());
    for (size_t i = 0; i < v.size(); ++i) v[i] = Vec3(m.v[3 * i], m.v[3 * i + 1], m.v[3 * i + 2]);
    std::vector<Tri> t(m.triangles());
    for (size_t i = 0; i < t.size(); ++i) t[i] = Tri(m.t[3 * i], m.t[3 * i + 1], m.t[3 * i + 2]);
    uint64_t t0 = peers::now_ns();
    auto model = std::make_shared<L::BVHModel<BV>>();
    model->beginModel(static_cast<int>(t.size()), static_cast<int>(v.size()));
    model->addSubModel(v, t);
    model->endModel();
    model->computeLocalAABB();
    ns = static_cast<double>(peers::now_ns() - t0);
    return model;
}

// The per-pose query, through the library's direct path or its generic entry
// point (see README: "Which path is fastest").
template <class BV>
struct Query {
    const L::BVHModel<BV>& a;
    const L::BVHModel<BV>& b;
    Transform tb = identity();
    bool direct;
    CollisionRequest creq;
    CollisionResult cres;
    DistanceRequest dreq;
    DistanceResult dres;
#if defined(PEER_COAL)
    coal::ComputeCollision ccol;
    // Made only for distance runs: coal has no distance for some of the BVs.
    std::unique_ptr<coal::ComputeDistance> cdist;
#endif

    Query(const L::BVHModel<BV>& a_, const L::BVHModel<BV>& b_, Mode mode, bool direct_)
        : a(a_),
          b(b_),
          direct(direct_),
#if defined(PEER_FCL)
          // No contact points or normals: only the triangle pairs are needed.
          creq(mode == Mode::All ? std::numeric_limits<size_t>::max() : 1, false)
#else
          creq(coal::NO_REQUEST, mode == Mode::All ? std::numeric_limits<size_t>::max() : 1),
          ccol(&a_, &b_)
#endif
    {
#if defined(PEER_COAL)
        if (mode == Mode::Distance) cdist = std::make_unique<coal::ComputeDistance>(&a_, &b_);
#endif
    }

    size_t collide(const Transform& ta) {
        cres.clear();
        if (!direct) return L::collide(&a, ta, &b, tb, creq, cres);
#if defined(PEER_FCL)
        return collide_node(ta);
#else
        return ccol(ta, tb, creq, cres);
#endif
    }

    double distance(const Transform& ta) {
        dres.clear();
        if (!direct) return L::distance(&a, ta, &b, tb, dreq, dres);
#if defined(PEER_FCL)
        return distance_node(ta);
#else
        return (*cdist)(ta, tb, dreq, dres);
#endif
    }

#if defined(PEER_FCL)
    // FCL has no cached functor: its direct path is the traversal node that
    // fcl::collide's dispatch table would pick, without the table and solver.
    size_t collide_node(const Transform& ta);
    double distance_node(const Transform& ta);
#endif
};

#if defined(PEER_FCL)
template <class Node, class BV>
size_t fcl_oriented_collide(const fcl::BVHModel<BV>& a, const Transform& ta, const fcl::BVHModel<BV>& b,
                            const Transform& tb, const CollisionRequest& req, CollisionResult& res) {
    Node node;
    fcl::detail::initialize(node, a, ta, b, tb, req, res);
    fcl::detail::collide(&node);
    return res.numContacts();
}

template <class Node, class BV>
double fcl_oriented_distance(const fcl::BVHModel<BV>& a, const Transform& ta, const fcl::BVHModel<BV>& b,
                             const Transform& tb, const DistanceRequest& req, DistanceResult& res) {
    Node node;
    fcl::detail::initialize(node, a, ta, b, tb, req, res);
    fcl::detail::distance(&node);
    return res.min_distance;
}

template <>
size_t Query<BvObbrss>::collide_node(const Transform& ta) {
    return fcl_oriented_collide<fcl::detail::MeshCollisionTraversalNodeOBBRSS<double>>(a, ta, b, tb, creq, cres);
}
template <>
size_t Query<BvObb>::collide_node(const Transform& ta) {
    return fcl_oriented_collide<fcl::detail::MeshCollisionTraversalNodeOBB<double>>(a, ta, b, tb, creq, cres);
}
template <>
size_t Query<BvRss>::collide_node(const Transform& ta) {
    return fcl_oriented_collide<fcl::detail::MeshCollisionTraversalNodeRSS<double>>(a, ta, b, tb, creq, cres);
}
// AABB and k-DOP trees cannot be rotated: FCL's only path copies both models and
// transforms their vertices on every call (fcl::collide does exactly that).
template <>
size_t Query<BvKdop18>::collide_node(const Transform& ta) {
    return L::collide(&a, ta, &b, tb, creq, cres);
}
template <>
size_t Query<BvAabb>::collide_node(const Transform& ta) {
    return L::collide(&a, ta, &b, tb, creq, cres);
}
template <>
double Query<BvObbrss>::distance_node(const Transform& ta) {
    return fcl_oriented_distance<fcl::detail::MeshDistanceTraversalNodeOBBRSS<double>>(a, ta, b, tb, dreq, dres);
}
template <>
double Query<BvRss>::distance_node(const Transform& ta) {
    return fcl_oriented_distance<fcl::detail::MeshDistanceTraversalNodeRSS<double>>(a, ta, b, tb, dreq, dres);
}
template <>
double Query<BvObb>::distance_node(const Transform&) {
    die("distance needs --bv obbrss or rss");
}
template <>
double Query<BvKdop18>::distance_node(const Transform&) {
    die("distance needs --bv obbrss or rss");
}
template <>
double Query<BvAabb>::distance_node(const Transform&) {
    die("distance needs --bv obbrss or rss");
}
#endif

template <class BV>
int run(const peers::Mesh& ma, const peers::Mesh& mb, const std::vector<peers::Pose>& poses, const Options& o) {
    double build_a, build_b;
    auto a = build<BV>(ma, build_a);
    auto b = build<BV>(mb, build_b);
    std::vector<Transform> tfs;
    tfs.reserve(poses.size());
    for (auto& p : poses) tfs.push_back(to_transform(p));

    Query<BV> q(*a, *b, o.mode, o.direct);
    std::vector<double> samples;
    samples.reserve(tfs.size() * o.reps);
    std::vector<std::string> lines(tfs.size());
    char buf[128];
    uint64_t total = 0;
    for (long rep = 0; rep < o.reps; ++rep) {
        for (size_t i = 0; i < tfs.size(); ++i) {
            uint64_t t0 = peers::now_ns();
            switch (o.mode) {
                case Mode::All: {
                    size_t n = q.collide(tfs[i]);
                    uint64_t dt = peers::now_ns() - t0;
                    samples.push_back(static_cast<double>(dt));
                    total += dt;
                    std::snprintf(buf, sizeof buf, "pairs %zu", n);
                    break;
                }
                case Mode::First: {
                    q.collide(tfs[i]);
                    uint64_t dt = peers::now_ns() - t0;
                    samples.push_back(static_cast<double>(dt));
                    total += dt;
                    std::snprintf(buf, sizeof buf, "hit %d", q.cres.isCollision() ? 1 : 0);
                    break;
                }
                case Mode::Distance: {
                    double d = q.distance(tfs[i]);
                    uint64_t dt = peers::now_ns() - t0;
                    samples.push_back(static_cast<double>(dt));
                    total += dt;
                    std::snprintf(buf, sizeof buf, "distance %.9g %ld %ld", d, static_cast<long>(q.dres.b1),
                                  static_cast<long>(q.dres.b2));
                    break;
                }
            }
            if (rep == 0) {
                lines[i] = buf;
            } else if (lines[i] != buf) {
                die("pose " + std::to_string(i) + ": repetition " + std::to_string(rep) + " answered '" + buf +
                    "', the first '" + lines[i] + "'");
            }
        }
    }
    for (auto& l : lines) std::printf("%s\n", l.c_str());
    auto s = peers::summarize(samples);
    std::printf("# lib %s %s\n", LIB_NAME, LIB_VERSION);
    std::printf("# bv %s\n", o.bv.c_str());
    std::printf("# mode %s\n", o.mode == Mode::All ? "all" : o.mode == Mode::First ? "first" : "distance");
    std::printf("# path %s\n", o.direct ? "direct" : "api");
    std::printf("# mesh_a %s %zu\n", ma.path.c_str(), ma.triangles());
    std::printf("# mesh_b %s %zu\n", mb.path.c_str(), mb.triangles());
    std::printf("# build_us %.1f %.1f\n", build_a / 1e3, build_b / 1e3);
    std::printf("# queries %zu\n", s.n);
    std::printf("# query_us median %.3f mean %.3f min %.3f\n", s.median / 1e3, s.mean / 1e3, s.min / 1e3);
    std::printf("# total_ms %.3f\n", static_cast<double>(total) / 1e6);
    return 0;
}

const char* USAGE =
    "usage: w5_mesh --lib fcl|coal [--bv obbrss|obb|rss|kdop18|aabb] A B POSES "
    "[--mode all|first|distance] [--reps N] [--path direct|api]";

}  // namespace

int main(int argc, char** argv) {
    peers::prog_name() = "w5_mesh";
    peers::Args args(argc, argv, {"--help"});
    if (args.has("--help")) {
        std::printf("%s\n", USAGE);
        return 0;
    }
    args.only({"--lib", "--bv", "--mode", "--reps", "--path"});
    if (args.positional.size() != 3) die(std::string("expected A B POSES; ") + USAGE);
    std::string lib = args.get("--lib", LIB_NAME);
    if (lib != LIB_NAME) die("this build runs --lib " LIB_NAME ", not " + lib + " (call target/peers/w5_mesh)");
    Options o;
    o.bv = args.get("--bv", "obbrss");
    std::string mode = args.get("--mode", "all");
    if (mode == "all")
        o.mode = Mode::All;
    else if (mode == "first")
        o.mode = Mode::First;
    else if (mode == "distance")
        o.mode = Mode::Distance;
    else
        die("--mode takes all, first or distance, not " + mode);
    o.reps = args.get_int("--reps", 1, 1);
    std::string path = args.get("--path", "direct");
    if (path != "direct" && path != "api") die("--path takes direct or api, not " + path);
    o.direct = path == "direct";
    if (o.mode == Mode::Distance && o.bv != "obbrss" && o.bv != "rss")
        die("--mode distance needs --bv obbrss or rss (the " LIB_NAME " distance traversals)");

    peers::Mesh a = peers::load_mesh(args.positional[0]);
    peers::Mesh b = peers::load_mesh(args.positional[1]);
    auto poses = peers::load_poses(args.positional[2]);
    if (o.bv == "obbrss") return run<BvObbrss>(a, b, poses, o);
    if (o.bv == "obb") return run<BvObb>(a, b, poses, o);
    if (o.bv == "rss") return run<BvRss>(a, b, poses, o);
    if (o.bv == "kdop18") return run<BvKdop18>(a, b, poses, o);
    if (o.bv == "aabb") return run<BvAabb>(a, b, poses, o);
    die("--bv takes obbrss, obb, rss, kdop18 or aabb, not " + o.bv);
}
