// The cySampleElim peer of mesh-sampling's blue_noise example: Yuksel's own
// C++ weighted sample elimination (cySampleElim.h of cyCodeBase, which is not
// part of this repository) on candidates the example writes.
//
//   cy_sample_elim CANDIDATES.f32 N AREA OUT.f32
//
// CANDIDATES.f32 holds M little-endian float32 x, y, z triples on a surface
// of area AREA. The M points are eliminated to N with the library's default
// weight function and parameters (alpha = 8, weight limiting on with
// beta = 0.65 and gamma = 1.5), Euclidean 3D distances, and the weight radius
// 2 r_max of a 2D domain of area AREA, r_max = sqrt(AREA / (2 sqrt(3) N)):
// the settings of trilux's `blue_noise` with a uniform density. The N kept
// points go to OUT.f32 in the same format, and one JSON line goes to stdout:
//
//   {"ms": <the Eliminate call alone>, "threads": T, "parallel": "..."}
//
// cySampleElim itself is sequential; only its k-d tree build runs in
// parallel, and only when built against TBB (define TRILUX_CY_TBB and link
// -ltbb): then T is TBB's thread count, otherwise 1.
//
// Build: g++ -O3 -march=native [-DTRILUX_CY_TBB] -I CYCODEBASE
//            cy_sample_elim.cpp -o cy_sample_elim [-ltbb]
// (the example does this itself with `--peer-cy auto`).

#ifdef TRILUX_CY_TBB
#include <tbb/info.h>
#include <tbb/parallel_invoke.h>
#define _CY_PARALLEL_LIB tbb
#endif

#include "cySampleElim.h"
#include "cyVector.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace {

int fail(const char* what, const char* detail) {
    std::fprintf(stderr, "cy_sample_elim: %s%s\n", what, detail);
    return 1;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 5) {
        std::fprintf(stderr, "usage: %s CANDIDATES.f32 N AREA OUT.f32\n", argv[0]);
        return 2;
    }
    std::FILE* in = std::fopen(argv[1], "rb");
    if (!in) return fail("cannot open ", argv[1]);
    std::vector<float> xyz;
    float buffer[3 * 4096];
    size_t got;
    while ((got = std::fread(buffer, sizeof(float), 3 * 4096, in)) > 0) {
        xyz.insert(xyz.end(), buffer, buffer + got);
    }
    std::fclose(in);
    if (xyz.size() % 3 != 0) return fail("not a whole number of xyz triples in ", argv[1]);
    const size_t m = xyz.size() / 3;
    char* end = nullptr;
    const unsigned long long n_arg = std::strtoull(argv[2], &end, 10);
    if (*end != '\0' || n_arg == 0 || n_arg >= m) {
        return fail("N must be a count between 1 and the candidate count - 1, got ", argv[2]);
    }
    const size_t n = static_cast<size_t>(n_arg);
    const double area = std::strtod(argv[3], &end);
    if (*end != '\0' || !(area > 0.0)) return fail("AREA must be > 0, got ", argv[3]);

    std::vector<cy::Vec3f> candidates(m);
    for (size_t i = 0; i < m; i++) {
        candidates[i] = cy::Vec3f(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    }
    std::vector<cy::Vec3f> kept(n);
    cy::WeightedSampleElimination<cy::Vec3f, float, 3> elimination;
    // The surface is a 2D domain in 3D: r_max of N disks over AREA.
    const float r_max = elimination.GetMaxPoissonDiskRadius(2, n, static_cast<float>(area));

    const auto start = std::chrono::steady_clock::now();
    elimination.Eliminate(candidates.data(), m, kept.data(), n, false, 2.0f * r_max, 2);
    const auto stop = std::chrono::steady_clock::now();
    const double ms = std::chrono::duration<double, std::milli>(stop - start).count();

    std::FILE* out = std::fopen(argv[4], "wb");
    if (!out) return fail("cannot create ", argv[4]);
    for (const cy::Vec3f& p : kept) {
        const float v[3] = {p.x, p.y, p.z};
        if (std::fwrite(v, sizeof(float), 3, out) != 3) return fail("cannot write ", argv[4]);
    }
    if (std::fclose(out) != 0) return fail("cannot write ", argv[4]);
#ifdef TRILUX_CY_TBB
    const int threads = tbb::info::default_concurrency();
    const char* parallel = "k-d tree build only (TBB)";
#else
    const int threads = 1;
    const char* parallel = "none";
#endif
    std::printf("{\"ms\": %.3f, \"threads\": %d, \"parallel\": \"%s\", \"points\": %zu}\n", ms,
                threads, parallel, n);
    return 0;
}
