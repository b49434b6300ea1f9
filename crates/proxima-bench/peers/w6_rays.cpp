// W6 peer harness: closest hit of rays against one mesh with Embree (3.13 from
// Debian; README.md beside this file says why not 4).
//
//   w6_rays --lib embree MESH RAYS [--threads K] [--reps N]
//           [--modes single,packet,stream] [--quality high|medium|low]
//           [--build-threads N] [--config EMBREE_CONFIG] [--brute N] [--clock wall|cpu]
//
// Prints one line per ray, `hit TRI T` (T with 9 significant digits) or `hit -`,
// from rtcIntersect1; then `#` lines: the build time, and for every mode the
// median ns per ray over the repetitions on 1 thread and on K threads.
// RAYS: binary (`PXRAYS01`, u64 count, 7 little-endian f32 per ray: origin,
// direction, tmax; tmax may be +inf) or text (7 numbers a line, `#` comments).
#include "common.hpp"

#include <embree3/rtcore.h>

#include <pmmintrin.h>
#include <xmmintrin.h>

#include <time.h>

#include <atomic>
#include <limits>
#include <thread>

using peers::die;

namespace {

struct Ray {
    float o[3], d[3], tmax;
};

struct Hit {
    unsigned tri;  // RTC_INVALID_GEOMETRY_ID: no hit
    float t;
    bool operator==(const Hit& h) const { return tri == h.tri && (tri == RTC_INVALID_GEOMETRY_ID || t == h.t); }
};

std::vector<Ray> load_rays(const std::string& path) {
    std::string data = peers::read_file(path);
    std::vector<Ray> rays;
    if (data.compare(0, 8, "PXRAYS01") == 0) {
        if (data.size() < 16) die(path + ": binary ray file shorter than its 16-byte header");
        uint64_t n;
        std::memcpy(&n, data.data() + 8, 8);
        if (data.size() != 16 + 28 * n)
            die(path + ": binary ray file declares " + std::to_string(n) + " rays (" + std::to_string(16 + 28 * n) +
                " bytes) but has " + std::to_string(data.size()) + " bytes");
        rays.resize(n);
        for (uint64_t i = 0; i < n; ++i) {
            float f[7];
            std::memcpy(f, data.data() + 16 + 28 * i, 28);
            rays[i] = {{f[0], f[1], f[2]}, {f[3], f[4], f[5]}, f[6]};
        }
    } else {
        std::istringstream in(data);
        std::string line;
        for (size_t n = 1; std::getline(in, line); ++n) {
            auto w = peers::words(line);
            if (w.empty()) continue;
            if (w.size() != 7) die(path + ": line " + std::to_string(n) + ": a ray needs 7 numbers");
            float f[7];
            for (int k = 0; k < 7; ++k)
                if (!peers::parse_f32(w[k], f[k])) die(path + ": line " + std::to_string(n) + ": bad number '" + w[k] + "'");
            rays.push_back({{f[0], f[1], f[2]}, {f[3], f[4], f[5]}, f[6]});
        }
    }
    for (size_t i = 0; i < rays.size(); ++i) {
        const Ray& r = rays[i];
        bool ok = std::isfinite(r.o[0]) && std::isfinite(r.o[1]) && std::isfinite(r.o[2]) && std::isfinite(r.d[0]) &&
                  std::isfinite(r.d[1]) && std::isfinite(r.d[2]) && !std::isnan(r.tmax) && r.tmax >= 0 &&
                  (r.d[0] != 0 || r.d[1] != 0 || r.d[2] != 0);
        if (!ok) die(path + ": ray " + std::to_string(i) + ": non-finite, zero direction or negative tmax");
    }
    if (rays.empty()) die(path + ": no rays");
    return rays;
}

void embree_error(void*, RTCError code, const char* str) {
    die(std::string("embree error ") + std::to_string(static_cast<int>(code)) + ": " + (str ? str : ""));
}

void fill1(RTCRayHit& rh, const Ray& r) {
    rh.ray.org_x = r.o[0];
    rh.ray.org_y = r.o[1];
    rh.ray.org_z = r.o[2];
    rh.ray.tnear = 0.0f;
    rh.ray.dir_x = r.d[0];
    rh.ray.dir_y = r.d[1];
    rh.ray.dir_z = r.d[2];
    rh.ray.time = 0.0f;
    rh.ray.tfar = r.tmax;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

Hit hit_of(unsigned geom, unsigned prim, float t) {
    return geom == RTC_INVALID_GEOMETRY_ID ? Hit{RTC_INVALID_GEOMETRY_ID, 0.0f} : Hit{prim, t};
}

// One ray at a time: rtcIntersect1 (Embree's documented path for incoherent rays).
void run_single(RTCScene scene, const Ray* rays, Hit* out, size_t n) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh;
    for (size_t i = 0; i < n; ++i) {
        fill1(rh, rays[i]);
        rtcIntersect1(scene, &ctx, &rh);
        out[i] = hit_of(rh.hit.geomID, rh.hit.primID, rh.ray.tfar);
    }
}

// Ray streams: rtcIntersect1M over chunks of consecutive rays (AOS layout).
void run_stream(RTCScene scene, const Ray* rays, Hit* out, size_t n) {
    constexpr size_t CHUNK = 256;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    alignas(64) RTCRayHit rh[CHUNK];
    for (size_t s = 0; s < n; s += CHUNK) {
        size_t m = std::min(CHUNK, n - s);
        for (size_t i = 0; i < m; ++i) fill1(rh[i], rays[s + i]);
        rtcIntersect1M(scene, &ctx, rh, static_cast<unsigned>(m), sizeof(RTCRayHit));
        for (size_t i = 0; i < m; ++i) out[s + i] = hit_of(rh[i].hit.geomID, rh[i].hit.primID, rh[i].ray.tfar);
    }
}

inline void intersect(const int* v, RTCScene s, RTCIntersectContext* c, RTCRayHit4* r) { rtcIntersect4(v, s, c, r); }
inline void intersect(const int* v, RTCScene s, RTCIntersectContext* c, RTCRayHit8* r) { rtcIntersect8(v, s, c, r); }
inline void intersect(const int* v, RTCScene s, RTCIntersectContext* c, RTCRayHit16* r) { rtcIntersect16(v, s, c, r); }

// Packets of N consecutive rays (SOA layout): rtcIntersect4/8/16.
template <int N, class Packet>
void run_packet(RTCScene scene, const Ray* rays, Hit* out, size_t n) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    alignas(64) Packet p;
    alignas(64) int valid[N];
    for (size_t s = 0; s < n; s += N) {
        size_t m = std::min<size_t>(N, n - s);
        for (int k = 0; k < N; ++k) {
            valid[k] = k < static_cast<int>(m) ? -1 : 0;
            const Ray& r = rays[s + (k < static_cast<int>(m) ? k : 0)];
            p.ray.org_x[k] = r.o[0];
            p.ray.org_y[k] = r.o[1];
            p.ray.org_z[k] = r.o[2];
            p.ray.tnear[k] = 0.0f;
            p.ray.dir_x[k] = r.d[0];
            p.ray.dir_y[k] = r.d[1];
            p.ray.dir_z[k] = r.d[2];
            p.ray.time[k] = 0.0f;
            p.ray.tfar[k] = r.tmax;
            p.ray.mask[k] = 0xFFFFFFFFu;
            p.ray.id[k] = 0;
            p.ray.flags[k] = 0;
            p.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
            p.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
        }
        intersect(valid, scene, &ctx, &p);
        for (size_t k = 0; k < m; ++k) out[s + k] = hit_of(p.hit.geomID[k], p.hit.primID[k], p.ray.tfar[k]);
    }
}

using Kernel = void (*)(RTCScene, const Ray*, Hit*, size_t);

// Embree's documented setting for every thread that traces rays: flush-to-zero
// and denormals-are-zero (its verbose mode warns without them).
void flush_denormals() {
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

// CPU time of the calling thread (ns): with `--clock cpu`, one-thread passes
// leave out the time the thread spent descheduled, as the Rust bench's default
// clock does, so the two stay comparable on a loaded machine.
uint64_t thread_cpu_ns() {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<uint64_t>(ts.tv_sec) * 1000000000u + static_cast<uint64_t>(ts.tv_nsec);
}

// Ns for one pass over all rays on `threads` threads (chunks of 1024 rays
// handed out by an atomic counter; threads are started per pass, ~0.1 ms): wall
// time, or the thread's CPU time for a one-thread pass when `cpu`.
double pass(Kernel k, RTCScene scene, const std::vector<Ray>& rays, std::vector<Hit>& out, unsigned threads,
            bool cpu = false) {
    if (threads <= 1 && cpu) {
        uint64_t t0 = thread_cpu_ns();
        k(scene, rays.data(), out.data(), rays.size());
        return static_cast<double>(thread_cpu_ns() - t0);
    }
    uint64_t t0 = peers::now_ns();
    if (threads <= 1) {
        k(scene, rays.data(), out.data(), rays.size());
    } else {
        constexpr size_t CHUNK = 1024;
        std::atomic<size_t> next{0};
        auto work = [&] {
            flush_denormals();
            for (;;) {
                size_t s = next.fetch_add(CHUNK);
                if (s >= rays.size()) return;
                k(scene, rays.data() + s, out.data() + s, std::min(CHUNK, rays.size() - s));
            }
        };
        std::vector<std::thread> pool;
        for (unsigned i = 1; i < threads; ++i) pool.emplace_back(work);
        work();
        for (auto& t : pool) t.join();
    }
    return static_cast<double>(peers::now_ns() - t0);
}

// Closest hit in double precision over every triangle (Möller–Trumbore; the
// oracle of --brute).
Hit brute(const peers::Mesh& m, const Ray& r) {
    Hit best{RTC_INVALID_GEOMETRY_ID, 0.0f};
    double bt = std::numeric_limits<double>::infinity();
    double o[3] = {r.o[0], r.o[1], r.o[2]}, d[3] = {r.d[0], r.d[1], r.d[2]};
    for (size_t i = 0; i < m.triangles(); ++i) {
        const float* a = &m.v[3 * m.t[3 * i]];
        const float* b = &m.v[3 * m.t[3 * i + 1]];
        const float* c = &m.v[3 * m.t[3 * i + 2]];
        double e1[3], e2[3], p[3], s[3], q[3];
        for (int k = 0; k < 3; ++k) {
            e1[k] = double(b[k]) - a[k];
            e2[k] = double(c[k]) - a[k];
            s[k] = o[k] - a[k];
        }
        p[0] = d[1] * e2[2] - d[2] * e2[1];
        p[1] = d[2] * e2[0] - d[0] * e2[2];
        p[2] = d[0] * e2[1] - d[1] * e2[0];
        double det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
        if (det == 0) continue;
        double u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) / det;
        if (u < 0 || u > 1) continue;
        q[0] = s[1] * e1[2] - s[2] * e1[1];
        q[1] = s[2] * e1[0] - s[0] * e1[2];
        q[2] = s[0] * e1[1] - s[1] * e1[0];
        double v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) / det;
        if (v < 0 || u + v > 1) continue;
        double t = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
        if (t < 0 || t > r.tmax || t >= bt) continue;
        bt = t;
        best = {static_cast<unsigned>(i), static_cast<float>(t)};
    }
    return best;
}

const char* USAGE =
    "usage: w6_rays --lib embree MESH RAYS [--threads K] [--reps N] [--modes single,packet,stream] "
    "[--quality high|medium|low] [--build-threads N] [--config EMBREE_CONFIG] [--brute N] [--clock wall|cpu]";

}  // namespace

int main(int argc, char** argv) {
    peers::prog_name() = "w6_rays";
    peers::Args args(argc, argv, {"--help"});
    if (args.has("--help")) {
        std::printf("%s\n", USAGE);
        return 0;
    }
    args.only({"--lib", "--threads", "--reps", "--modes", "--quality", "--build-threads", "--config", "--brute",
               "--clock"});
    if (args.positional.size() != 2) die(std::string("expected MESH RAYS; ") + USAGE);
    if (args.get("--lib", "embree") != "embree") die("--lib takes embree");
    unsigned hw = std::max(1u, std::thread::hardware_concurrency());
    unsigned threads = static_cast<unsigned>(args.get_int("--threads", hw, 1));
    long reps = args.get_int("--reps", 5, 1);
    long brute_n = args.get_int("--brute", 0, 0);
    std::string clock = args.get("--clock", "wall");
    if (clock != "wall" && clock != "cpu") die("--clock takes wall or cpu");
    std::string quality = args.get("--quality", "high");
    RTCBuildQuality q = quality == "high"     ? RTC_BUILD_QUALITY_HIGH
                        : quality == "medium" ? RTC_BUILD_QUALITY_MEDIUM
                        : quality == "low"    ? RTC_BUILD_QUALITY_LOW
                                              : (die("--quality takes high, medium or low"), RTC_BUILD_QUALITY_HIGH);
    std::vector<std::string> modes;
    {
        std::string m = args.get("--modes", "single,packet,stream");
        std::istringstream s(m);
        std::string w;
        while (std::getline(s, w, ','))
            if (!w.empty()) {
                if (w != "single" && w != "packet" && w != "stream") die("--modes takes single, packet, stream");
                modes.push_back(w);
            }
    }

    peers::Mesh mesh = peers::load_mesh(args.positional[0]);
    std::vector<Ray> rays = load_rays(args.positional[1]);

    flush_denormals();
    std::string cfg = args.get("--config", "");
    if (args.has("--build-threads"))
        cfg += (cfg.empty() ? "" : ",") + std::string("threads=") + std::to_string(args.get_int("--build-threads", 0, 1));
    RTCDevice dev = rtcNewDevice(cfg.empty() ? nullptr : cfg.c_str());
    if (!dev) die("rtcNewDevice failed (error " + std::to_string(static_cast<int>(rtcGetDeviceError(nullptr))) + ")");
    rtcSetDeviceErrorFunction(dev, embree_error, nullptr);

    // A static scene (no DYNAMIC, COMPACT or ROBUST flag) with the high-quality
    // (spatial split) build Embree recommends for static geometry.
    uint64_t t0 = peers::now_ns();
    RTCScene scene = rtcNewScene(dev);
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_NONE);
    rtcSetSceneBuildQuality(scene, q);
    RTCGeometry geom = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(geom, q);
    auto* vb = static_cast<float*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), mesh.vertices()));
    auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                              3 * sizeof(unsigned), mesh.triangles()));
    std::memcpy(vb, mesh.v.data(), mesh.v.size() * sizeof(float));
    std::memcpy(ib, mesh.t.data(), mesh.t.size() * sizeof(unsigned));
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(scene);
    double build_ns = static_cast<double>(peers::now_ns() - t0);

    int width = rtcGetDeviceProperty(dev, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED)  ? 16
                : rtcGetDeviceProperty(dev, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED) ? 8
                                                                                        : 4;
    Kernel packet = width == 16  ? run_packet<16, RTCRayHit16>
                    : width == 8 ? run_packet<8, RTCRayHit8>
                                 : run_packet<4, RTCRayHit4>;

    // The answers: rtcIntersect1, one thread.
    std::vector<Hit> ref(rays.size()), got(rays.size());
    pass(run_single, scene, rays, ref, 1);
    for (const Hit& h : ref) {
        if (h.tri == RTC_INVALID_GEOMETRY_ID)
            std::printf("hit -\n");
        else
            std::printf("hit %u %.9g\n", h.tri, static_cast<double>(h.t));
    }

    std::printf("# lib embree %s\n", RTC_VERSION_STRING);
    std::printf("# mesh %s %zu\n", mesh.path.c_str(), mesh.triangles());
    std::printf("# rays %zu\n", rays.size());
    std::printf("# build_ms %.3f quality %s\n", build_ns / 1e6, quality.c_str());
    std::printf("# device_config %s\n", cfg.empty() ? "default" : cfg.c_str());
    std::printf("# packet_width %d\n", width);
    std::printf("# threads 1 %u\n", threads);
    std::printf("# clock %s\n", clock.c_str());
    // Each mode: `# ns_per_ray MODE median_1thread median_Kthreads`; rounds take
    // turns over the modes so that load from elsewhere hits them alike.
    std::vector<std::vector<double>> t1(modes.size()), tk(modes.size());
    size_t mismatches = 0;
    for (long r = 0; r < reps; ++r) {
        for (size_t m = 0; m < modes.size(); ++m) {
            Kernel k = modes[m] == "single" ? run_single : modes[m] == "packet" ? packet : run_stream;
            t1[m].push_back(pass(k, scene, rays, got, 1, clock == "cpu") / rays.size());
            for (size_t i = 0; i < rays.size(); ++i) mismatches += !(got[i] == ref[i]);
            tk[m].push_back(pass(k, scene, rays, got, threads) / rays.size());
            for (size_t i = 0; i < rays.size(); ++i) mismatches += !(got[i] == ref[i]);
        }
    }
    for (size_t m = 0; m < modes.size(); ++m) {
        std::string name = modes[m] == "packet" ? "packet" + std::to_string(width) : modes[m];
        std::printf("# ns_per_ray %s %.1f %.1f\n", name.c_str(), peers::summarize(t1[m]).median,
                    peers::summarize(tk[m]).median);
    }
    std::printf("# mode_mismatches %zu\n", mismatches);
    if (brute_n > 0) {
        // Agreement: both miss, or the same t up to 1e-5 relative (f32 vs f64);
        // a tie is an equal t on another triangle (an edge or a vertex).
        size_t n = std::min<size_t>(brute_n, rays.size()), differ = 0, ties = 0;
        for (size_t i = 0; i < n; ++i) {
            Hit b = brute(mesh, rays[i]);
            const Hit& e = ref[i];
            bool both = b.tri != RTC_INVALID_GEOMETRY_ID && e.tri != RTC_INVALID_GEOMETRY_ID;
            if (!both) {
                differ += b.tri != e.tri;
            } else if (std::fabs(b.t - e.t) > 1e-5f * std::max(1.0f, std::fabs(b.t))) {
                ++differ;
            } else {
                ties += b.tri != e.tri;
            }
        }
        std::printf("# brute %zu rays: %zu differ, %zu ties (equal t, another triangle)\n", n, differ, ties);
    }
    rtcReleaseScene(scene);
    rtcReleaseDevice(dev);
    return 0;
}
