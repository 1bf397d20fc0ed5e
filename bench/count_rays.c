/* Counts the ray queries a process makes through Embree 4, for comparing renderers by
 * work done rather than by time alone.
 *
 *   cc -O2 -shared -fPIC -o count_rays.so bench/count_rays.c -ldl
 *   HT_RAY_COUNT_FILE=rays.json LD_PRELOAD=$PWD/count_rays.so python bench/cycles.py ...
 *
 * At exit it writes {"closest": N, "shadow": M} to $HT_RAY_COUNT_FILE: closest-hit queries
 * (rtcIntersect*) and any-hit queries (rtcOccluded*). Packet queries count their active
 * lanes. Nothing is written when the variable is unset or when the process made no query,
 * so a parent process that only launches the renderer does not overwrite the counts.
 *
 * Cycles 5 calls rtcTraversableIntersect1 / rtcTraversableOccluded1, which Embree 4.4
 * forwards to rtcIntersect1 / rtcOccluded1 through its own PLT. Both layers are
 * interposed, and only the outermost interposed call on a thread counts, so a query is
 * counted once whichever way a given Embree build routes it. */

#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

/* Only pointers cross this shim, so Embree's types can stay opaque. */
typedef struct RTCSceneTy *RTCScene;
typedef struct RTCTraversableTy *RTCTraversable;
struct RTCRayHit;
struct RTCRay;
struct RTCIntersectArguments;
struct RTCOccludedArguments;

/* Per-thread counters, each on its own cache line, so that counting costs an uncontended
 * add instead of a shared line bouncing between cores on every ray. Threads beyond
 * MAX_THREADS share slots, which the atomic adds keep correct. */
#define MAX_THREADS 1024
struct slot {
    uint64_t closest, shadow;
} __attribute__((aligned(64)));
static struct slot slots[MAX_THREADS];
static unsigned next_slot;
/* A preloaded library gets static TLS: initial-exec avoids __tls_get_addr on every ray. */
static __thread struct slot *mine __attribute__((tls_model("initial-exec")));
/* Depth of interposed calls on this thread: nested ones are the same query. */
static __thread int depth __attribute__((tls_model("initial-exec")));

/* The definition the shim hides. RTLD_NEXT searches only the global scope, but bpy loads
 * Embree as a dependency of a module dlopen'ed with RTLD_LOCAL: then ask the already
 * loaded library itself. */
static void *real(const char *name)
{
    void *f = dlsym(RTLD_NEXT, name);
    if (!f) {
        void *embree = dlopen("libembree4.so.4", RTLD_LAZY | RTLD_NOLOAD);
        if (embree)
            f = dlsym(embree, name);
    }
    if (!f) {
        fprintf(stderr, "count_rays: no Embree definition of %s\n", name);
        abort();
    }
    return f;
}

static void count(int shadow, uint64_t n)
{
    if (depth != 0)
        return;
    if (!mine)
        mine = &slots[__atomic_fetch_add(&next_slot, 1, __ATOMIC_RELAXED) % MAX_THREADS];
    __atomic_fetch_add(shadow ? &mine->shadow : &mine->closest, n, __ATOMIC_RELAXED);
}

/* Active lanes of a packet: Embree marks them with -1 in the valid mask. */
static uint64_t lanes(const int *valid, int width)
{
    uint64_t n = 0;
    for (int i = 0; i < width; i++)
        n += valid[i] != 0;
    return n;
}

/* The real function is looked up once (a benign race: every thread stores the same value)
 * and called with the depth raised, so that Embree's own forwarding is not counted again. */
#define FORWARD(type, name, params, args, shadow, n)                    \
    void name params                                                    \
    {                                                                   \
        static type cached;                                             \
        type fn = __atomic_load_n(&cached, __ATOMIC_RELAXED);           \
        if (!fn) {                                                      \
            fn = (type)real(#name);                                     \
            __atomic_store_n(&cached, fn, __ATOMIC_RELAXED);            \
        }                                                               \
        count(shadow, n);                                               \
        depth++;                                                        \
        fn args;                                                        \
        depth--;                                                        \
    }

typedef void (*intersect1_fn)(RTCScene, struct RTCRayHit *, struct RTCIntersectArguments *);
typedef void (*occluded1_fn)(RTCScene, struct RTCRay *, struct RTCOccludedArguments *);
typedef void (*intersect_t1_fn)(RTCTraversable, struct RTCRayHit *,
                                struct RTCIntersectArguments *);
typedef void (*occluded_t1_fn)(RTCTraversable, struct RTCRay *, struct RTCOccludedArguments *);
typedef void (*intersectn_fn)(const int *, RTCScene, void *, struct RTCIntersectArguments *);
typedef void (*occludedn_fn)(const int *, RTCScene, void *, struct RTCOccludedArguments *);
typedef void (*intersect_tn_fn)(const int *, RTCTraversable, void *,
                                struct RTCIntersectArguments *);
typedef void (*occluded_tn_fn)(const int *, RTCTraversable, void *,
                               struct RTCOccludedArguments *);

FORWARD(intersect1_fn, rtcIntersect1,
        (RTCScene s, struct RTCRayHit *r, struct RTCIntersectArguments *a), (s, r, a), 0, 1)
FORWARD(occluded1_fn, rtcOccluded1,
        (RTCScene s, struct RTCRay *r, struct RTCOccludedArguments *a), (s, r, a), 1, 1)
FORWARD(intersect_t1_fn, rtcTraversableIntersect1,
        (RTCTraversable s, struct RTCRayHit *r, struct RTCIntersectArguments *a), (s, r, a),
        0, 1)
FORWARD(occluded_t1_fn, rtcTraversableOccluded1,
        (RTCTraversable s, struct RTCRay *r, struct RTCOccludedArguments *a), (s, r, a), 1, 1)

#define PACKETS(n)                                                                      \
    FORWARD(intersectn_fn, rtcIntersect##n,                                             \
            (const int *v, RTCScene s, void *r, struct RTCIntersectArguments *a),       \
            (v, s, r, a), 0, lanes(v, n))                                               \
    FORWARD(occludedn_fn, rtcOccluded##n,                                               \
            (const int *v, RTCScene s, void *r, struct RTCOccludedArguments *a),        \
            (v, s, r, a), 1, lanes(v, n))                                               \
    FORWARD(intersect_tn_fn, rtcTraversableIntersect##n,                                \
            (const int *v, RTCTraversable s, void *r, struct RTCIntersectArguments *a), \
            (v, s, r, a), 0, lanes(v, n))                                               \
    FORWARD(occluded_tn_fn, rtcTraversableOccluded##n,                                  \
            (const int *v, RTCTraversable s, void *r, struct RTCOccludedArguments *a),  \
            (v, s, r, a), 1, lanes(v, n))

PACKETS(4)
PACKETS(8)
PACKETS(16)

__attribute__((destructor)) static void write_counts(void)
{
    const char *path = getenv("HT_RAY_COUNT_FILE");
    uint64_t closest = 0, shadow = 0;
    for (int i = 0; i < MAX_THREADS; i++) {
        closest += __atomic_load_n(&slots[i].closest, __ATOMIC_RELAXED);
        shadow += __atomic_load_n(&slots[i].shadow, __ATOMIC_RELAXED);
    }
    if (!path || !*path || closest + shadow == 0)
        return;
    FILE *f = fopen(path, "w");
    if (!f) {
        perror(path);
        return;
    }
    fprintf(f, "{\"closest\": %llu, \"shadow\": %llu}\n", (unsigned long long)closest,
            (unsigned long long)shadow);
    fclose(f);
}
