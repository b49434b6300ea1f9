// Shared by the C++ peer harnesses (README.md beside this file): mesh and pose
// readers with Proxima's conventions, a clock, statistics, argument helpers.
//
// Meshes load exactly as `proxima::io::load` reads them, so triangle indices and
// f32 vertex values agree with Proxima's: OBJ `v`/`f` lines (polygons fanned
// (0,i,i+1), 1-based or negative indices, FCL's `<nverts> <ntris>` header line
// skipped), STL binary (size 84 + 50 n) or ASCII with bit-identical corners
// welded. Poses are design §4.2's pose files. Bad input ends the program with one
// line `PROG: FILE: line N: what` and exit code 2.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

namespace peers {

inline const char*& prog_name() {
    static const char* name = "peer";
    return name;
}

// One line on stderr, exit code 2 (bad input or usage).
[[noreturn]] inline void die(const std::string& msg) {
    std::fprintf(stderr, "%s: %s\n", prog_name(), msg.c_str());
    std::exit(2);
}

struct Mesh {
    std::string path;
    std::vector<float> v;     // x y z per vertex
    std::vector<uint32_t> t;  // 3 vertex indices per triangle, the file's order
    size_t vertices() const { return v.size() / 3; }
    size_t triangles() const { return t.size() / 3; }
};

inline std::string read_file(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) die(path + ": cannot open: " + std::strerror(errno));
    std::ostringstream s;
    s << f.rdbuf();
    return s.str();
}

inline bool parse_f32(const std::string& tok, float& out) {
    char* end = nullptr;
    out = std::strtof(tok.c_str(), &end);
    return end && *end == '\0' && !tok.empty();
}

inline bool parse_f64(const std::string& tok, double& out) {
    char* end = nullptr;
    out = std::strtod(tok.c_str(), &end);
    return end && *end == '\0' && !tok.empty();
}

inline std::vector<std::string> words(const std::string& line) {
    std::vector<std::string> w;
    std::istringstream s(line.substr(0, line.find('#')));
    std::string tok;
    while (s >> tok) w.push_back(tok);
    return w;
}

inline Mesh parse_obj(const std::string& path, const std::string& text) {
    Mesh m;
    m.path = path;
    std::istringstream in(text);
    std::string line;
    std::vector<uint32_t> poly;
    for (size_t n = 1; std::getline(in, line); ++n) {
        auto w = words(line);
        if (w.empty()) continue;
        auto where = path + ": line " + std::to_string(n) + ": ";
        if (w[0] == "v") {
            if (w.size() < 4) die(where + "vertex needs 3 coordinates");
            for (int k = 1; k <= 3; ++k) {
                float x;
                if (!parse_f32(w[k], x) || !std::isfinite(x))
                    die(where + "bad vertex coordinate '" + w[k] + "'");
                m.v.push_back(x);
            }
        } else if (w[0] == "f") {
            poly.clear();
            long nv = static_cast<long>(m.vertices());
            for (size_t k = 1; k < w.size(); ++k) {
                std::string idx = w[k].substr(0, w[k].find('/'));
                char* end = nullptr;
                long i = std::strtol(idx.c_str(), &end, 10);
                if (idx.empty() || *end != '\0' || i == 0) die(where + "bad face index '" + w[k] + "'");
                long r = i > 0 ? i - 1 : nv + i;
                if (r < 0 || r >= nv) die(where + "face index " + idx + " out of range");
                poly.push_back(static_cast<uint32_t>(r));
            }
            if (poly.size() < 3) die(where + "face needs at least 3 corners");
            for (size_t k = 1; k + 1 < poly.size(); ++k) {
                m.t.push_back(poly[0]);
                m.t.push_back(poly[k]);
                m.t.push_back(poly[k + 1]);
            }
        }
        // Anything else (vt, vn, groups, FCL's header line) is skipped.
    }
    if (m.t.empty()) die(path + ": no triangles");
    return m;
}

// Welds corners with bit-identical coordinates (-0 as 0), as Proxima does.
struct Welder {
    Mesh& m;
    std::unordered_map<uint64_t, std::vector<uint32_t>> seen;
    explicit Welder(Mesh& mesh) : m(mesh) {}
    uint32_t add(float x, float y, float z) {
        if (x == 0.0f) x = 0.0f;
        if (y == 0.0f) y = 0.0f;
        if (z == 0.0f) z = 0.0f;
        uint32_t bx, by, bz;
        std::memcpy(&bx, &x, 4);
        std::memcpy(&by, &y, 4);
        std::memcpy(&bz, &z, 4);
        uint64_t h = (uint64_t(bx) * 0x9E3779B97F4A7C15ull) ^ (uint64_t(by) << 21) ^ (uint64_t(bz) * 0xC2B2AE3D27D4EB4Full);
        auto& bucket = seen[h];
        for (uint32_t i : bucket)
            if (m.v[3 * i] == x && m.v[3 * i + 1] == y && m.v[3 * i + 2] == z) return i;
        uint32_t i = static_cast<uint32_t>(m.vertices());
        m.v.insert(m.v.end(), {x, y, z});
        bucket.push_back(i);
        return i;
    }
};

inline Mesh parse_stl(const std::string& path, const std::string& data) {
    Mesh m;
    m.path = path;
    Welder weld(m);
    if (data.size() >= 84) {
        uint32_t n;
        std::memcpy(&n, data.data() + 80, 4);
        if (data.size() == 84 + 50ull * n) {
            for (uint32_t i = 0; i < n; ++i) {
                const char* rec = data.data() + 84 + 50ull * i + 12;  // skip the normal
                for (int c = 0; c < 3; ++c) {
                    float p[3];
                    std::memcpy(p, rec + 12 * c, 12);
                    for (float x : p)
                        if (!std::isfinite(x)) die(path + ": triangle " + std::to_string(i) + ": non-finite coordinate");
                    m.t.push_back(weld.add(p[0], p[1], p[2]));
                }
            }
            if (m.t.empty()) die(path + ": no triangles");
            return m;
        }
    }
    size_t start = data.find_first_not_of(" \t\r\n");
    if (start == std::string::npos || data.compare(start, 5, "solid") != 0)
        die(path + ": neither binary STL (size 84 + 50 n) nor ASCII STL");
    std::istringstream in(data);
    std::string line;
    for (size_t n = 1; std::getline(in, line); ++n) {
        auto w = words(line);
        if (w.empty() || w[0] != "vertex") continue;
        float p[3];
        if (w.size() < 4) die(path + ": line " + std::to_string(n) + ": vertex needs 3 coordinates");
        for (int k = 0; k < 3; ++k)
            if (!parse_f32(w[k + 1], p[k]) || !std::isfinite(p[k]))
                die(path + ": line " + std::to_string(n) + ": bad coordinate '" + w[k + 1] + "'");
        m.t.push_back(weld.add(p[0], p[1], p[2]));
    }
    if (m.t.size() % 3 != 0) die(path + ": facet with other than 3 vertices");
    if (m.t.empty()) die(path + ": no triangles");
    return m;
}

inline bool ends_with_ci(const std::string& s, const std::string& suffix) {
    if (s.size() < suffix.size()) return false;
    for (size_t i = 0; i < suffix.size(); ++i)
        if (std::tolower(static_cast<unsigned char>(s[s.size() - suffix.size() + i])) != suffix[i]) return false;
    return true;
}

// OBJ or STL by extension.
inline Mesh load_mesh(const std::string& path) {
    std::string data = read_file(path);
    if (ends_with_ci(path, ".stl")) return parse_stl(path, data);
    if (ends_with_ci(path, ".obj")) return parse_obj(path, data);
    die(path + ": unknown mesh format (OBJ or STL)");
}

// Row-major rotation r, translation t: p' = R p + t.
struct Pose {
    double r[9];
    double t[3];
};

// Parses the 12 numbers of a pose from words w[from..from+12); checks rigidity as
// design §7.1 does (|R^T R - I| <= 1e-3, det > 0).
inline Pose parse_pose(const std::vector<std::string>& w, size_t from, const std::string& where) {
    if (w.size() != from + 12) die(where + "a pose needs 12 numbers, got " + std::to_string(w.size() - from));
    Pose p;
    for (int k = 0; k < 12; ++k) {
        double x;
        if (!parse_f64(w[from + k], x) || !std::isfinite(x)) die(where + "bad number '" + w[from + k] + "'");
        (k < 9 ? p.r[k] : p.t[k - 9]) = x;
    }
    const double* r = p.r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            double d = r[i] * r[j] + r[3 + i] * r[3 + j] + r[6 + i] * r[6 + j] - (i == j ? 1.0 : 0.0);
            if (std::fabs(d) > 1e-3) die(where + "not a rotation (R^T R != I)");
        }
    double det = r[0] * (r[4] * r[8] - r[5] * r[7]) - r[1] * (r[3] * r[8] - r[5] * r[6]) + r[2] * (r[3] * r[7] - r[4] * r[6]);
    if (det <= 0) die(where + "not a rotation (det <= 0)");
    return p;
}

// A pose file: one pose a line, `#` comments and blank lines skipped.
inline std::vector<Pose> load_poses(const std::string& path) {
    std::istringstream in(read_file(path));
    std::vector<Pose> poses;
    std::string line;
    for (size_t n = 1; std::getline(in, line); ++n) {
        auto w = words(line);
        if (w.empty()) continue;
        poses.push_back(parse_pose(w, 0, path + ": line " + std::to_string(n) + ": "));
    }
    if (poses.empty()) die(path + ": no poses");
    return poses;
}

inline uint64_t now_ns() {
    return static_cast<uint64_t>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
            .count());
}

struct Summary {
    double median = 0, mean = 0, min = 0;
    size_t n = 0;
};

// Median, mean, min of samples in ns, returned in the same unit.
inline Summary summarize(std::vector<double> x) {
    Summary s;
    s.n = x.size();
    if (x.empty()) return s;
    std::sort(x.begin(), x.end());
    s.median = x.size() % 2 ? x[x.size() / 2] : 0.5 * (x[x.size() / 2 - 1] + x[x.size() / 2]);
    double sum = 0;
    for (double v : x) sum += v;
    s.mean = sum / x.size();
    s.min = x.front();
    return s;
}

// `--flag value` arguments and positionals, in any order.
struct Args {
    std::vector<std::string> positional;
    std::vector<std::pair<std::string, std::string>> flags;

    // `switches` are flags without a value.
    Args(int argc, char** argv, const std::vector<std::string>& switches) {
        for (int i = 1; i < argc; ++i) {
            std::string a = argv[i];
            if (a.rfind("--", 0) == 0) {
                if (std::find(switches.begin(), switches.end(), a) != switches.end()) {
                    flags.push_back({a, ""});
                } else {
                    if (i + 1 >= argc) die(a + " needs a value");
                    flags.push_back({a, argv[++i]});
                }
            } else {
                positional.push_back(a);
            }
        }
    }
    bool has(const std::string& f) const {
        for (auto& kv : flags)
            if (kv.first == f) return true;
        return false;
    }
    std::string get(const std::string& f, const std::string& dflt) const {
        std::string v = dflt;
        for (auto& kv : flags)
            if (kv.first == f) v = kv.second;
        return v;
    }
    long get_int(const std::string& f, long dflt, long lo) const {
        if (!has(f)) return dflt;
        std::string v = get(f, "");
        char* end = nullptr;
        long x = std::strtol(v.c_str(), &end, 10);
        if (v.empty() || *end != '\0' || x < lo) die(f + " needs an integer >= " + std::to_string(lo) + ", got '" + v + "'");
        return x;
    }
    // Dies on a flag not in `known` (value flags and switches).
    void only(const std::vector<std::string>& known) const {
        for (auto& kv : flags)
            if (std::find(known.begin(), known.end(), kv.first) == known.end()) die("unknown option " + kv.first);
    }
};

}  // namespace peers
