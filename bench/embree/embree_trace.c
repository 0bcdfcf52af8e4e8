/* embree_trace: the Embree side of candela's traversal benchmark (see README.md).
 *
 * Loads a ray file written by `candela bench traversal --export FILE` (one triangle mesh and
 * named ray batches), builds an Embree 3 scene over the mesh (RTC_SCENE_FLAG_NONE, i.e. robust
 * mode off, with the requested build quality) and times rtcIntersect1 (closest-hit batches) or
 * rtcOccluded1 (any-hit batches) over a batch on N threads (pthreads; the threads take chunks of
 * 1024 consecutive rays from a shared atomic counter, like candela's side). Tracing threads
 * run with flush-to-zero and denormals-are-zero on, as Embree asks. EMBREE_CONFIG in the
 * environment is passed to rtcNewDevice (e.g. EMBREE_CONFIG=verbose=2 prints the builder).
 *
 * Usage:
 *   embree_trace RAYS [--quality low|medium|high] [--build-reps N] [--robust]
 *                     [--threads 1,2] [--reps N] [--hits OUT] [--serve]
 *
 * --robust sets RTC_SCENE_FLAG_ROBUST (Embree's watertight mode, which candela's kernel always
 * matches; the benchmark's `medium-robust` column).
 *
 * Without --serve it traces every batch --reps times for each thread count and prints one
 * `trace ...` line per run. With --serve (used by `candela bench traversal --embree`) it reads
 * commands from stdin, one per line, and answers each with one line on stdout:
 *   trace SET THREADS   ->  trace set=SET threads=THREADS rays=N seconds=S cpu_seconds=C
 *   hits PATH           ->  hits written=PATH      (t of the last run of every batch)
 *   quit
 * Every answer line starts with a keyword; errors are reported as `error: ...` on stderr with
 * a non-zero exit status.
 *
 * Ray file (little endian), version 1:
 *   "CNDLRAY1", u32 vertices, u32 triangles, u32 sets, u32 reserved
 *   f32 positions[3*vertices], u32 indices[3*triangles]
 *   per set: u32 kind (0 closest hit, 1 any hit), u32 count, char name[16] (NUL padded),
 *            count x {f32 ox, oy, oz, tnear, dx, dy, dz, tfar}
 * Hit file (written by --hits / `hits`):
 *   "CNDLHIT1", u32 sets, u32 reserved, per set: u32 count, f32 t[count]
 *   t = hit distance, or +inf for a miss; for any-hit batches 0 = occluded, +inf = not.
 */
#define _GNU_SOURCE
#include <embree3/rtcore.h>
#include <math.h>
#include <pmmintrin.h>
#include <xmmintrin.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define CHUNK 1024
#define MAX_SETS 16
#define MAX_THREADS 64

typedef struct {
    float ox, oy, oz, tnear, dx, dy, dz, tfar;
} Ray;

typedef struct {
    uint32_t kind;
    uint32_t count;
    char name[17];
    Ray *rays;
    float *t;
} RaySet;

static void die(const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "error: ");
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "\n");
    va_end(ap);
    exit(1);
}

static double now(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static void read_exact(FILE *f, void *dst, size_t bytes, const char *path, const char *what) {
    if (fread(dst, 1, bytes, f) != bytes)
        die("ray file '%s' is truncated (while reading %s); re-export it with "
            "`candela bench traversal --export`",
            path, what);
}

/* ---- Embree memory monitor: bytes currently allocated by the device, and the peak. ---- */
static int64_t mem_now = 0, mem_peak = 0;
static bool monitor(void *user, ssize_t bytes, bool post) {
    (void)user;
    (void)post;
    int64_t v = __atomic_add_fetch(&mem_now, (int64_t)bytes, __ATOMIC_RELAXED);
    int64_t p = __atomic_load_n(&mem_peak, __ATOMIC_RELAXED);
    while (v > p && !__atomic_compare_exchange_n(&mem_peak, &p, v, 1, __ATOMIC_RELAXED,
                                                 __ATOMIC_RELAXED)) {
    }
    return true;
}

static void on_error(void *user, enum RTCError code, const char *str) {
    (void)user;
    die("Embree error %d: %s", (int)code, str ? str : "");
}

/* ---- tracing ---- */
typedef struct {
    RTCScene scene;
    RaySet *set;
    uint64_t next;     /* atomic chunk counter */
    uint64_t cpu_ns;   /* atomic: CPU time of the tracing threads */
} Job;

static uint64_t thread_cpu_ns(void) {
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

static void *worker(void *arg) {
    Job *job = arg;
    RaySet *s = job->set;
    /* As Embree's documentation asks of every thread that traces rays. */
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
    uint64_t c0 = thread_cpu_ns();
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (;;) {
        uint64_t c = __atomic_fetch_add(&job->next, 1, __ATOMIC_RELAXED);
        uint64_t begin = c * CHUNK;
        if (begin >= s->count) break;
        uint64_t end = begin + CHUNK < s->count ? begin + CHUNK : s->count;
        for (uint64_t i = begin; i < end; i++) {
            const Ray *r = &s->rays[i];
            if (s->kind == 0) {
                struct RTCRayHit rh;
                rh.ray.org_x = r->ox;
                rh.ray.org_y = r->oy;
                rh.ray.org_z = r->oz;
                rh.ray.tnear = r->tnear;
                rh.ray.dir_x = r->dx;
                rh.ray.dir_y = r->dy;
                rh.ray.dir_z = r->dz;
                rh.ray.time = 0.0f;
                rh.ray.tfar = r->tfar;
                rh.ray.mask = 0xffffffffu;
                rh.ray.id = 0;
                rh.ray.flags = 0;
                rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
                rtcIntersect1(job->scene, &ctx, &rh);
                s->t[i] = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID ? rh.ray.tfar : INFINITY;
            } else {
                struct RTCRay ray;
                ray.org_x = r->ox;
                ray.org_y = r->oy;
                ray.org_z = r->oz;
                ray.tnear = r->tnear;
                ray.dir_x = r->dx;
                ray.dir_y = r->dy;
                ray.dir_z = r->dz;
                ray.time = 0.0f;
                ray.tfar = r->tfar;
                ray.mask = 0xffffffffu;
                ray.id = 0;
                ray.flags = 0;
                rtcOccluded1(job->scene, &ctx, &ray);
                s->t[i] = ray.tfar < 0.0f ? 0.0f : INFINITY;
            }
        }
    }
    __atomic_fetch_add(&job->cpu_ns, thread_cpu_ns() - c0, __ATOMIC_RELAXED);
    return NULL;
}

/* Returns the wall time in seconds; *cpu gets the tracing threads' CPU seconds. */
static double trace(RTCScene scene, RaySet *s, int threads, double *cpu) {
    Job job = {scene, s, 0, 0};
    pthread_t tid[MAX_THREADS];
    double t0 = now();
    for (int i = 0; i < threads; i++)
        if (pthread_create(&tid[i], NULL, worker, &job) != 0) die("cannot start a thread");
    for (int i = 0; i < threads; i++) pthread_join(tid[i], NULL);
    double wall = now() - t0;
    *cpu = job.cpu_ns * 1e-9;
    return wall;
}

static void write_hits(const char *path, RaySet *sets, uint32_t n) {
    FILE *f = fopen(path, "wb");
    if (!f) die("cannot create hit file '%s'", path);
    uint32_t hdr[2] = {n, 0};
    int ok = fwrite("CNDLHIT1", 1, 8, f) == 8 && fwrite(hdr, 4, 2, f) == 2;
    for (uint32_t i = 0; ok && i < n; i++)
        ok = fwrite(&sets[i].count, 4, 1, f) == 1 &&
             fwrite(sets[i].t, 4, sets[i].count, f) == sets[i].count;
    if (fclose(f) != 0 || !ok) die("cannot write hit file '%s'", path);
}

static int cmp_double(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv) {
    const char *path = NULL, *hits = NULL, *quality_name = "medium";
    int reps = 1, build_reps = 1, serve = 0, robust = 0;
    int thread_list[MAX_THREADS], n_threads = 0;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--quality") && v) {
            quality_name = v;
            i++;
        } else if (!strcmp(a, "--reps") && v) {
            reps = atoi(v);
            i++;
        } else if (!strcmp(a, "--build-reps") && v) {
            build_reps = atoi(v);
            i++;
        } else if (!strcmp(a, "--hits") && v) {
            hits = v;
            i++;
        } else if (!strcmp(a, "--threads") && v) {
            char *copy = strdup(v), *save = NULL;
            for (char *tok = strtok_r(copy, ",", &save); tok && n_threads < MAX_THREADS;
                 tok = strtok_r(NULL, ",", &save))
                thread_list[n_threads++] = atoi(tok);
            free(copy);
            i++;
        } else if (!strcmp(a, "--serve")) {
            serve = 1;
        } else if (!strcmp(a, "--robust")) {
            robust = 1;
        } else if (a[0] == '-') {
            die("unknown option '%s' (see the comment at the top of embree_trace.c)", a);
        } else {
            path = a;
        }
    }
    if (!path) die("usage: embree_trace RAYS [--quality low|medium|high] [--build-reps N] "
                   "[--threads 1,2] [--reps N] [--hits OUT] [--serve]");
    if (n_threads == 0) {
        thread_list[0] = 1;
        thread_list[1] = 2;
        n_threads = 2;
    }
    for (int i = 0; i < n_threads; i++)
        if (thread_list[i] < 1 || thread_list[i] > MAX_THREADS) die("bad thread count");
    if (reps < 1 || build_reps < 1) die("--reps and --build-reps must be at least 1");
    enum RTCBuildQuality quality;
    if (!strcmp(quality_name, "low")) quality = RTC_BUILD_QUALITY_LOW;
    else if (!strcmp(quality_name, "medium")) quality = RTC_BUILD_QUALITY_MEDIUM;
    else if (!strcmp(quality_name, "high")) quality = RTC_BUILD_QUALITY_HIGH;
    else die("unknown --quality '%s' (low, medium or high)", quality_name);

    /* ---- load ---- */
    FILE *f = fopen(path, "rb");
    if (!f) die("cannot open ray file '%s'; create it with `candela bench traversal --export %s`",
                path, path);
    char magic[8];
    read_exact(f, magic, 8, path, "the header");
    if (memcmp(magic, "CNDLRAY1", 8) != 0)
        die("'%s' is not a candela ray file (version 1)", path);
    uint32_t hdr[4];
    read_exact(f, hdr, sizeof hdr, path, "the header");
    uint32_t nv = hdr[0], nt = hdr[1], n_sets = hdr[2];
    if (n_sets > MAX_SETS) die("ray file '%s' has %u batches (at most %d)", path, n_sets, MAX_SETS);
    float *positions = malloc((size_t)nv * 12 + 16);
    uint32_t *indices = malloc((size_t)nt * 12 + 16);
    if (!positions || !indices) die("out of memory");
    read_exact(f, positions, (size_t)nv * 12, path, "the vertices");
    read_exact(f, indices, (size_t)nt * 12, path, "the triangles");
    for (size_t i = 0; i < (size_t)nt * 3; i++)
        if (indices[i] >= nv) die("ray file '%s' is corrupt: vertex index out of range", path);
    RaySet sets[MAX_SETS];
    for (uint32_t i = 0; i < n_sets; i++) {
        uint32_t kc[2];
        read_exact(f, kc, 8, path, "a batch header");
        sets[i].kind = kc[0];
        sets[i].count = kc[1];
        if (sets[i].kind > 1) die("ray file '%s' is corrupt: batch kind %u", path, sets[i].kind);
        read_exact(f, sets[i].name, 16, path, "a batch name");
        sets[i].name[16] = 0;
        sets[i].rays = malloc((size_t)sets[i].count * sizeof(Ray) + 1);
        sets[i].t = malloc((size_t)sets[i].count * 4 + 1);
        if (!sets[i].rays || !sets[i].t) die("out of memory");
        for (uint32_t k = 0; k < sets[i].count; k++) sets[i].t[k] = NAN; /* not traced yet */
        read_exact(f, sets[i].rays, (size_t)sets[i].count * sizeof(Ray), path, "the rays");
    }
    fclose(f);

    /* ---- build ---- */
    const char *config = getenv("EMBREE_CONFIG");
    RTCDevice device = rtcNewDevice(config);
    if (!device) die("cannot create an Embree device (error %d)", (int)rtcGetDeviceError(NULL));
    rtcSetDeviceErrorFunction(device, on_error, NULL);
    rtcSetDeviceMemoryMonitorFunction(device, monitor, NULL);
    double build_times[64];
    if (build_reps > 64) build_reps = 64;
    RTCScene scene = NULL;
    int64_t buffers = 0, total = 0;
    for (int b = 0; b < build_reps; b++) {
        if (scene) rtcReleaseScene(scene);
        int64_t m0 = __atomic_load_n(&mem_now, __ATOMIC_RELAXED);
        scene = rtcNewScene(device);
        rtcSetSceneFlags(scene, robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
        rtcSetSceneBuildQuality(scene, quality);
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        rtcSetGeometryBuildQuality(g, quality);
        float *vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 12, nv);
        uint32_t *ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 12, nt);
        memcpy(vb, positions, (size_t)nv * 12);
        memcpy(ib, indices, (size_t)nt * 12);
        rtcCommitGeometry(g);
        rtcAttachGeometry(scene, g);
        rtcReleaseGeometry(g);
        int64_t m1 = __atomic_load_n(&mem_now, __ATOMIC_RELAXED);
        double t0 = now();
        rtcCommitScene(scene);
        build_times[b] = now() - t0;
        int64_t m2 = __atomic_load_n(&mem_now, __ATOMIC_RELAXED);
        buffers = m1 - m0;
        total = m2 - m0;
    }
    qsort(build_times, build_reps, sizeof(double), cmp_double);
    printf("embree version=%ld isa_note=runtime-dispatch quality=%s vertices=%u triangles=%u\n",
           (long)rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_VERSION), quality_name, nv, nt);
    printf("build quality=%s robust=%d seconds=%.6f builds=%d bytes_total=%lld bytes_buffers=%lld "
           "bytes_peak=%lld\n",
           quality_name, robust, build_times[build_reps / 2], build_reps, (long long)total,
           (long long)buffers, (long long)mem_peak);
    fflush(stdout);

    if (!serve) {
        for (int r = 0; r < reps; r++)
            for (uint32_t i = 0; i < n_sets; i++)
                for (int k = 0; k < n_threads; k++) {
                    double cpu, s = trace(scene, &sets[i], thread_list[k], &cpu);
                    printf("trace set=%s threads=%d rays=%u seconds=%.6f cpu_seconds=%.6f "
                           "mrays=%.3f\n",
                           sets[i].name, thread_list[k], sets[i].count, s, cpu,
                           sets[i].count / s * 1e-6);
                    fflush(stdout);
                }
        if (hits) write_hits(hits, sets, n_sets);
    } else {
        char line[4096];
        while (fgets(line, sizeof line, stdin)) {
            char cmd[32] = {0}, arg1[4000] = {0};
            int threads = 0;
            int n = sscanf(line, "%31s %3999s %d", cmd, arg1, &threads);
            if (n < 1) continue;
            if (!strcmp(cmd, "quit")) break;
            if (!strcmp(cmd, "trace") && n == 3) {
                uint32_t i = 0;
                while (i < n_sets && strcmp(sets[i].name, arg1) != 0) i++;
                if (i == n_sets) die("no ray batch named '%s' in '%s'", arg1, path);
                if (threads < 1 || threads > MAX_THREADS) die("bad thread count %d", threads);
                double cpu, s = trace(scene, &sets[i], threads, &cpu);
                printf("trace set=%s threads=%d rays=%u seconds=%.6f cpu_seconds=%.6f\n", arg1,
                       threads, sets[i].count, s, cpu);
            } else if (!strcmp(cmd, "hits") && n >= 2) {
                write_hits(arg1, sets, n_sets);
                printf("hits written=%s\n", arg1);
            } else {
                die("unknown command '%s'", line);
            }
            fflush(stdout);
        }
    }
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
    return 0;
}
