// World peer harness (issue 13): a `proxima world` trace (design §7.1) run with
// FCL 0.7's broad phase and mesh collision; README.md beside this file.
//
//   fcl_world [world] TRACE [--first] [--reps N] [--update all|moved] [--path direct|api]
//
// One shared BVHModel<OBBRSS> per `mesh`, one CollisionObject per `add`, one
// DynamicAABBTreeCollisionManager. A frame is the lines between two `contacts`:
// `pose` = setTransform + computeAABB, then at `contacts` the manager's update()
// and collide() with a callback that runs the unlimited-contacts mesh collide
// (one contact per intersecting triangle pair; `--first`: one at most) on every
// pair not ignored. Prints `contacts P T` (`--first`: `contacts P`) exactly as
// `proxima world` does, `ray skip` and `sphere skip` for the queries FCL 0.7 has no
// counterpart for, then `#` timing lines. The optional leading word `world` lets
// the harness stand in for `proxima world` in scripts.
#include "common.hpp"

#include <fcl/config.h>
#include <fcl/fcl.h>
#include <fcl/narrowphase/detail/traversal/collision/mesh_collision_traversal_node.h>
#include <fcl/narrowphase/detail/traversal/collision_node.h>

#include <limits>
#include <map>
#include <memory>
#include <set>
#include <unordered_map>

using peers::die;
using Model = fcl::BVHModel<fcl::OBBRSSd>;
using Object = fcl::CollisionObjectd;

namespace {

enum class Op { Mesh, Add, Pose, Remove, Ignore, Contacts, Ray, Sphere };

struct Line {
    Op op;
    size_t line;
    uint64_t id = 0, id2 = 0;
    std::string name;
    peers::Pose pose{};
};

std::string dir_of(const std::string& path) {
    size_t s = path.rfind('/');
    return s == std::string::npos ? std::string(".") : path.substr(0, s);
}

bool parse_u64(const std::string& s, uint64_t& out) {
    if (s.empty() || s.size() > 20) return false;
    for (char c : s)
        if (c < '0' || c > '9') return false;
    errno = 0;
    char* end = nullptr;
    out = std::strtoull(s.c_str(), &end, 10);
    return errno == 0 && *end == '\0';
}

// Reads the whole trace and loads its meshes (validation that does not depend on
// the world's state happens here; ids are checked while running).
std::vector<Line> parse(const std::string& path, std::map<std::string, peers::Mesh>& meshes) {
    std::istringstream in(peers::read_file(path));
    std::vector<Line> ops;
    std::string text;
    for (size_t n = 1; std::getline(in, text); ++n) {
        auto w = peers::words(text);
        if (w.empty()) continue;
        std::string where = path + ": line " + std::to_string(n) + ": ";
        auto arity = [&](size_t k) {
            if (w.size() != k + 1)
                die(where + "'" + w[0] + "' needs " + std::to_string(k) + " values, got " + std::to_string(w.size() - 1));
        };
        auto id = [&](size_t i) {
            uint64_t v;
            if (!parse_u64(w[i], v)) die(where + "bad id '" + w[i] + "'");
            return v;
        };
        Line l;
        l.op = Op::Contacts;
        l.line = n;
        if (w[0] == "mesh") {
            arity(2);
            l.op = Op::Mesh;
            l.name = w[1];
            if (meshes.count(w[1])) die(where + "mesh '" + w[1] + "' already defined");
            std::string file = w[2][0] == '/' ? w[2] : dir_of(path) + "/" + w[2];
            if (!std::ifstream(file)) die(where + "cannot open mesh file " + file);
            meshes[w[1]] = peers::load_mesh(file);
        } else if (w[0] == "add") {
            arity(2);
            l.op = Op::Add;
            l.id = id(1);
            l.name = w[2];
            if (!meshes.count(w[2])) die(where + "unknown mesh '" + w[2] + "'");
        } else if (w[0] == "pose") {
            if (w.size() != 14) die(where + "'pose' needs an id and 12 numbers");
            l.op = Op::Pose;
            l.id = id(1);
            l.pose = peers::parse_pose(w, 2, where);
        } else if (w[0] == "remove") {
            arity(1);
            l.op = Op::Remove;
            l.id = id(1);
        } else if (w[0] == "ignore") {
            arity(2);
            l.op = Op::Ignore;
            l.id = id(1);
            l.id2 = id(2);
        } else if (w[0] == "contacts") {
            arity(0);
            l.op = Op::Contacts;
        } else if (w[0] == "ray") {
            arity(7);
            l.op = Op::Ray;
        } else if (w[0] == "sphere") {
            arity(4);
            l.op = Op::Sphere;
        } else {
            die(where + "unknown operation '" + w[0] + "'");
        }
        ops.push_back(l);
    }
    return ops;
}

struct Options {
    bool first = false;
    bool update_all = true;
    bool direct = true;
    long reps = 1;
};

struct World;

// What the collide callback needs.
struct PairData {
    World* world;
    fcl::CollisionRequestd req;
    fcl::CollisionResultd res;
    bool direct;
    uint64_t pairs = 0, tris = 0;
};

struct World {
    std::string trace;
    const std::map<std::string, std::shared_ptr<Model>>& models;
    fcl::DynamicAABBTreeCollisionManagerd manager;
    // Each object's user data points at its id (read in the pair callback).
    struct Entry {
        uint64_t id;
        std::unique_ptr<Object> obj;
    };
    std::unordered_map<uint64_t, std::unique_ptr<Entry>> objects;
    std::set<std::pair<uint64_t, uint64_t>> ignored;
    std::vector<Object*> moved;

    World(std::string t, const std::map<std::string, std::shared_ptr<Model>>& m) : trace(std::move(t)), models(m) {}

    Object* find(uint64_t id, size_t line) {
        auto it = objects.find(id);
        if (it == objects.end()) die(trace + ": line " + std::to_string(line) + ": unknown id " + std::to_string(id));
        return it->second->obj.get();
    }

    static std::pair<uint64_t, uint64_t> key(uint64_t a, uint64_t b) { return a < b ? std::make_pair(a, b) : std::make_pair(b, a); }
};

bool on_pair(Object* o1, Object* o2, void* data) {
    auto* d = static_cast<PairData*>(data);
    World& w = *d->world;
    if (!w.ignored.empty()) {
        uint64_t a = static_cast<const World::Entry*>(o1->getUserData())->id;
        uint64_t b = static_cast<const World::Entry*>(o2->getUserData())->id;
        if (w.ignored.count(World::key(a, b))) return false;
    }
    d->res.clear();
    if (d->direct) {
        // The traversal fcl::collide would dispatch to for two OBBRSS meshes.
        fcl::detail::MeshCollisionTraversalNodeOBBRSS<double> node;
        fcl::detail::initialize(node, static_cast<const Model&>(*o1->collisionGeometry()), o1->getTransform(),
                                static_cast<const Model&>(*o2->collisionGeometry()), o2->getTransform(), d->req,
                                d->res);
        fcl::detail::collide(&node);
    } else {
        fcl::collide(o1, o2, d->req, d->res);
    }
    size_t n = d->res.numContacts();
    if (n > 0) {
        d->pairs += 1;
        d->tris += n;
    }
    return false;  // never stop: every pair is wanted
}

struct Timings {
    std::vector<double> frame_ns, pose_ns, update_ns, collide_ns;
    double other_ns = 0;
};

// Runs the trace once; appends result lines to `out` and times to `t`.
void run(const std::string& trace, const std::vector<Line>& ops, const std::map<std::string, std::shared_ptr<Model>>& models,
         const Options& o, std::vector<std::string>& out, Timings& t) {
    World w(trace, models);
    PairData pd{&w, fcl::CollisionRequestd(o.first ? 1 : std::numeric_limits<size_t>::max(), false), {}, o.direct};
    double frame_pose = 0;
    char buf[64];
    for (const Line& l : ops) {
        std::string where = trace + ": line " + std::to_string(l.line) + ": ";
        switch (l.op) {
            case Op::Mesh:
                break;
            case Op::Add: {
                if (w.objects.count(l.id)) die(where + "id " + std::to_string(l.id) + " already in use");
                uint64_t t0 = peers::now_ns();
                auto e = std::make_unique<World::Entry>();
                e->id = l.id;
                e->obj = std::make_unique<Object>(models.at(l.name), fcl::Transform3d::Identity());
                e->obj->setUserData(e.get());
                e->obj->computeAABB();
                w.manager.registerObject(e->obj.get());
                w.objects[l.id] = std::move(e);
                t.other_ns += peers::now_ns() - t0;
                break;
            }
            case Op::Pose: {
                Object* obj = w.find(l.id, l.line);
                uint64_t t0 = peers::now_ns();
                Eigen::Matrix3d r;
                const double* m = l.pose.r;
                r << m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8];
                obj->setTransform(r, Eigen::Vector3d(l.pose.t[0], l.pose.t[1], l.pose.t[2]));
                obj->computeAABB();
                if (!o.update_all) w.moved.push_back(obj);
                frame_pose += peers::now_ns() - t0;
                break;
            }
            case Op::Remove: {
                Object* obj = w.find(l.id, l.line);
                uint64_t t0 = peers::now_ns();
                w.manager.unregisterObject(obj);
                w.moved.erase(std::remove(w.moved.begin(), w.moved.end(), obj), w.moved.end());
                // The pair list names objects, not ids: a later object with this
                // id starts with no ignored pairs.
                for (auto it = w.ignored.begin(); it != w.ignored.end();)
                    it = (it->first == l.id || it->second == l.id) ? w.ignored.erase(it) : std::next(it);
                w.objects.erase(l.id);
                t.other_ns += peers::now_ns() - t0;
                break;
            }
            case Op::Ignore:
                w.find(l.id, l.line);
                w.find(l.id2, l.line);
                w.ignored.insert(World::key(l.id, l.id2));
                break;
            case Op::Contacts: {
                uint64_t t0 = peers::now_ns();
                if (o.update_all) {
                    w.manager.update();
                } else {
                    std::sort(w.moved.begin(), w.moved.end());
                    w.moved.erase(std::unique(w.moved.begin(), w.moved.end()), w.moved.end());
                    w.manager.update(w.moved);
                    w.moved.clear();
                }
                uint64_t t1 = peers::now_ns();
                pd.pairs = pd.tris = 0;
                w.manager.collide(&pd, on_pair);
                uint64_t t2 = peers::now_ns();
                t.pose_ns.push_back(frame_pose);
                t.update_ns.push_back(static_cast<double>(t1 - t0));
                t.collide_ns.push_back(static_cast<double>(t2 - t1));
                t.frame_ns.push_back(frame_pose + static_cast<double>(t2 - t0));
                frame_pose = 0;
                if (o.first)
                    std::snprintf(buf, sizeof buf, "contacts %llu", static_cast<unsigned long long>(pd.pairs));
                else
                    std::snprintf(buf, sizeof buf, "contacts %llu %llu", static_cast<unsigned long long>(pd.pairs),
                                  static_cast<unsigned long long>(pd.tris));
                out.push_back(buf);
                break;
            }
            case Op::Ray:
                out.push_back("ray skip");
                break;
            case Op::Sphere:
                out.push_back("sphere skip");
                break;
        }
    }
    // Unregister before the objects go (the manager holds raw pointers).
    w.manager.clear();
}

const char* USAGE = "usage: fcl_world [world] TRACE [--first] [--reps N] [--update all|moved] [--path direct|api]";

}  // namespace

int main(int argc, char** argv) {
    peers::prog_name() = "fcl_world";
    peers::Args args(argc, argv, {"--first", "--help"});
    if (args.has("--help")) {
        std::printf("%s\n", USAGE);
        return 0;
    }
    args.only({"--first", "--reps", "--update", "--path"});
    auto pos = args.positional;
    if (!pos.empty() && pos[0] == "world") pos.erase(pos.begin());
    if (pos.size() != 1) die(std::string("expected TRACE; ") + USAGE);
    Options o;
    o.first = args.has("--first");
    o.reps = args.get_int("--reps", 1, 1);
    std::string update = args.get("--update", "all");
    if (update != "all" && update != "moved") die("--update takes all or moved, not " + update);
    o.update_all = update == "all";
    std::string path = args.get("--path", "direct");
    if (path != "direct" && path != "api") die("--path takes direct or api, not " + path);
    o.direct = path == "direct";

    std::map<std::string, peers::Mesh> meshes;
    auto ops = parse(pos[0], meshes);
    std::map<std::string, std::shared_ptr<Model>> models;
    double build_ns = 0;
    size_t tris = 0;
    for (auto& kv : meshes) {
        const peers::Mesh& m = kv.second;
        std::vector<fcl::Vector3d> v(m.vertices());
        for (size_t i = 0; i < v.size(); ++i) v[i] = fcl::Vector3d(m.v[3 * i], m.v[3 * i + 1], m.v[3 * i + 2]);
        std::vector<fcl::Triangle> t(m.triangles());
        for (size_t i = 0; i < t.size(); ++i) t[i] = fcl::Triangle(m.t[3 * i], m.t[3 * i + 1], m.t[3 * i + 2]);
        uint64_t t0 = peers::now_ns();
        auto model = std::make_shared<Model>();
        model->beginModel(static_cast<int>(t.size()), static_cast<int>(v.size()));
        model->addSubModel(v, t);
        model->endModel();
        model->computeLocalAABB();
        build_ns += peers::now_ns() - t0;
        tris += t.size();
        models[kv.first] = model;
    }

    std::vector<std::string> first_out;
    Timings t;
    for (long rep = 0; rep < o.reps; ++rep) {
        std::vector<std::string> out;
        run(pos[0], ops, models, o, out, t);
        if (rep == 0)
            first_out = out;
        else if (out != first_out)
            die("repetition " + std::to_string(rep) + " printed other answers than the first");
    }
    for (auto& l : first_out) std::printf("%s\n", l.c_str());
    auto f = peers::summarize(t.frame_ns), p = peers::summarize(t.pose_ns), u = peers::summarize(t.update_ns),
         c = peers::summarize(t.collide_ns);
    std::printf("# lib fcl %s\n", FCL_VERSION);
    std::printf("# broadphase DynamicAABBTreeCollisionManager update %s\n", o.update_all ? "all" : "moved");
    std::printf("# bv obbrss path %s%s\n", o.direct ? "direct" : "api", o.first ? " first" : "");
    std::printf("# meshes %zu tris %zu build_ms %.3f\n", models.size(), tris, build_ns / 1e6);
    std::printf("# frames %zu reps %ld\n", f.n, o.reps);
    std::printf("# frame_us median %.3f mean %.3f\n", f.median / 1e3, f.mean / 1e3);
    std::printf("# poses_us median %.3f\n", p.median / 1e3);
    std::printf("# update_us median %.3f\n", u.median / 1e3);
    std::printf("# collide_us median %.3f\n", c.median / 1e3);
    std::printf("# other_us total %.3f\n", t.other_ns / 1e3 / o.reps);
    return 0;
}
