/* Embree 3 on the mesh benchmark's rays: the reference, measured on the same machine.
 *
 * Reads the bunny OBJ and the rays that `cargo run --release -p fray-mesh --example embree_rays`
 * writes (the exact primary and shadow rays of `cargo bench -p fray-mesh --bench packet`), builds
 * an Embree scene (default build quality), and times rtcIntersect1 (primary rays), rtcIntersect8
 * (8 consecutive rays: a 4x2 Morton block) and rtcOccluded1 (shadow rays) on 1 and 2 threads,
 * tiles of 256 rays handed out in order. Prints medians of 11 runs in Mrays/s.
 *
 * Build: cc -O2 -o embree_bench embree_bench.c -lembree3 -lpthread (Debian: libembree-dev).
 * Run:   ./embree_bench data/meshes/bunny00.obj rays.bin
 */
#include <embree3/rtcore.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define TILE 256
#define RUNS 11

static float *vertices; static unsigned *faces; static size_t nv, nf;
static float *prim; static size_t nprim;     /* origin, dir */
static float *shad; static size_t nshad;     /* origin, dir, lo, hi */
static RTCScene scene;
static atomic_size_t next_tile;
static int mode; /* 0 intersect1, 1 intersect8, 2 occluded1 */

static void load_obj(const char *path) {
    FILE *f = fopen(path, "r");
    if (!f) { perror(path); exit(1); }
    size_t cv = 1 << 16, cf = 1 << 16;
    vertices = malloc(cv * 3 * sizeof(float)); faces = malloc(cf * 3 * sizeof(unsigned));
    char line[512];
    while (fgets(line, sizeof line, f)) {
        if (line[0] == 'v' && line[1] == ' ') {
            if (nv == cv) { cv *= 2; vertices = realloc(vertices, cv * 3 * sizeof(float)); }
            sscanf(line + 2, "%f %f %f", &vertices[3 * nv], &vertices[3 * nv + 1], &vertices[3 * nv + 2]);
            nv++;
        } else if (line[0] == 'f' && line[1] == ' ') {
            unsigned a, b, c;
            if (sscanf(line + 2, "%u %u %u", &a, &b, &c) != 3) { fprintf(stderr, "face: %s", line); exit(1); }
            if (nf == cf) { cf *= 2; faces = realloc(faces, cf * 3 * sizeof(unsigned)); }
            faces[3 * nf] = a - 1; faces[3 * nf + 1] = b - 1; faces[3 * nf + 2] = c - 1;
            nf++;
        }
    }
    fclose(f);
}

static float *read_rays(FILE *f, size_t *n, size_t floats) {
    uint64_t count;
    if (fread(&count, 8, 1, f) != 1) { fprintf(stderr, "short ray file\n"); exit(1); }
    float *r = malloc(count * floats * sizeof(float));
    if (fread(r, sizeof(float) * floats, count, f) != count) { fprintf(stderr, "short ray file\n"); exit(1); }
    *n = count;
    return r;
}

static double now(void) {
    struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

static void *worker(void *out) {
    size_t hits = 0;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    size_t n = mode == 2 ? nshad : nprim;
    for (;;) {
        size_t start = atomic_fetch_add(&next_tile, TILE);
        if (start >= n) break;
        size_t end = start + TILE < n ? start + TILE : n;
        if (mode == 0) {
            for (size_t i = start; i < end; i++) {
                const float *r = prim + 6 * i;
                struct RTCRayHit rh;
                rh.ray.org_x = r[0]; rh.ray.org_y = r[1]; rh.ray.org_z = r[2];
                rh.ray.dir_x = r[3]; rh.ray.dir_y = r[4]; rh.ray.dir_z = r[5];
                rh.ray.tnear = 0.0f; rh.ray.tfar = INFINITY; rh.ray.time = 0.0f;
                rh.ray.mask = 0xFFFFFFFF; rh.ray.id = 0; rh.ray.flags = 0;
                rh.hit.geomID = RTC_INVALID_GEOMETRY_ID; rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
                rtcIntersect1(scene, &ctx, &rh);
                hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
            }
        } else if (mode == 1) {
            for (size_t i = start; i < end; i += 8) {
                struct RTCRayHit8 rh __attribute__((aligned(32)));
                int valid[8] __attribute__((aligned(32)));
                for (int j = 0; j < 8; j++) {
                    size_t k = i + j;
                    valid[j] = k < end ? -1 : 0;
                    const float *r = prim + 6 * (k < end ? k : start);
                    rh.ray.org_x[j] = r[0]; rh.ray.org_y[j] = r[1]; rh.ray.org_z[j] = r[2];
                    rh.ray.dir_x[j] = r[3]; rh.ray.dir_y[j] = r[4]; rh.ray.dir_z[j] = r[5];
                    rh.ray.tnear[j] = 0.0f; rh.ray.tfar[j] = INFINITY; rh.ray.time[j] = 0.0f;
                    rh.ray.mask[j] = 0xFFFFFFFF; rh.ray.id[j] = 0; rh.ray.flags[j] = 0;
                    rh.hit.geomID[j] = RTC_INVALID_GEOMETRY_ID; rh.hit.instID[0][j] = RTC_INVALID_GEOMETRY_ID;
                }
                rtcIntersect8(valid, scene, &ctx, &rh);
                for (int j = 0; j < 8; j++) hits += valid[j] && rh.hit.geomID[j] != RTC_INVALID_GEOMETRY_ID;
            }
        } else {
            for (size_t i = start; i < end; i++) {
                const float *r = shad + 8 * i;
                struct RTCRay ray;
                ray.org_x = r[0]; ray.org_y = r[1]; ray.org_z = r[2];
                ray.dir_x = r[3]; ray.dir_y = r[4]; ray.dir_z = r[5];
                ray.tnear = r[6]; ray.tfar = r[7]; ray.time = 0.0f;
                ray.mask = 0xFFFFFFFF; ray.id = 0; ray.flags = 0;
                rtcOccluded1(scene, &ctx, &ray);
                hits += ray.tfar < 0.0f; /* -inf when occluded */
            }
        }
    }
    *(size_t *)out = hits;
    return NULL;
}

static int cmp(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void run(const char *what, int m, int threads) {
    mode = m;
    double times[RUNS];
    size_t hits = 0;
    for (int run = -1; run < RUNS; run++) { /* run -1 warms up */
        pthread_t t[8]; size_t h[8];
        atomic_store(&next_tile, 0);
        double t0 = now();
        for (int i = 0; i < threads; i++) pthread_create(&t[i], NULL, worker, &h[i]);
        hits = 0;
        for (int i = 0; i < threads; i++) { pthread_join(t[i], NULL); hits += h[i]; }
        if (run >= 0) times[run] = now() - t0;
    }
    qsort(times, RUNS, sizeof(double), cmp);
    size_t n = m == 2 ? nshad : nprim;
    printf("%-34s %d thread(s): median %8.2f ms = %6.2f Mrays/s (min %.2f ms); %zu of %zu %s\n",
           what, threads, 1e3 * times[RUNS / 2], n / times[RUNS / 2] / 1e6, 1e3 * times[0], hits, n,
           m == 2 ? "occluded" : "hit");
}

int main(int argc, char **argv) {
    if (argc != 3) { fprintf(stderr, "usage: %s MESH.obj RAYS.bin\n", argv[0]); return 2; }
    load_obj(argv[1]);
    FILE *f = fopen(argv[2], "rb");
    if (!f) { perror(argv[2]); return 1; }
    prim = read_rays(f, &nprim, 6);
    shad = read_rays(f, &nshad, 8);
    fclose(f);
    RTCDevice device = rtcNewDevice(NULL);
    printf("Embree %d.%d.%d, %zu vertices, %zu triangles\n", RTC_VERSION_MAJOR, RTC_VERSION_MINOR,
           RTC_VERSION_PATCH, nv, nf);
    double t0 = now();
    scene = rtcNewScene(device);
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    float *vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv);
    unsigned *ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), nf);
    memcpy(vb, vertices, nv * 3 * sizeof(float));
    memcpy(ib, faces, nf * 3 * sizeof(unsigned));
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(scene);
    printf("scene build (Embree's own threads): %.2f ms\n", 1e3 * (now() - t0));
    for (int threads = 1; threads <= 2; threads++) {
        run("primary, rtcIntersect1", 0, threads);
        run("primary, rtcIntersect8 (4x2 blocks)", 1, threads);
        run("shadow, rtcOccluded1", 2, threads);
    }
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
    return 0;
}
