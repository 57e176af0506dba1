// PCG32 (O'Neill 2014, XSH-RR): small state, good statistics, and seekable
// streams, so each pixel gets its own sequence whatever thread renders it.
#include "ref.h"

// SplitMix64 finaliser: decorrelates (seed, pixel) pairs that differ in few bits.
static uint64_t mix64(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

void st_ref_rng_seed(st_ref_rng *r, uint64_t seed, uint64_t stream) {
    *r = (st_ref_rng){0};
    r->inc = (mix64(stream ^ 0x9e3779b97f4a7c15ull) << 1) | 1u; // must be odd
    st_ref_rng_u32(r);
    r->state += mix64(seed + 0x632be59bd9b4e019ull * (stream + 1));
    st_ref_rng_u32(r);
}

uint32_t st_ref_rng_u32(st_ref_rng *r) {
    uint64_t old = r->state;
    r->state = old * 6364136223846793005ull + r->inc;
    uint32_t xorshifted = (uint32_t)(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = (uint32_t)(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((-rot) & 31));
}

static double ld_uniform(st_ref_rng *r);
// Dimensions past the first LD_DIMS of a sample are plain PCG32 numbers: a
// sample of height fog draws hundreds (one per ratio-tracking collision),
// where the scrambled points cost 5x a PCG32 number and gain nothing
// measurable (tests/data/crosscheck/height_fog.json, 64 spp: per-sample
// variance 5.15e-5 with every dimension low-discrepancy, 5.23e-5 with 64,
// 1.07e-4 with none; CPU time 1.45x, 1.05x, 1x).
#define LD_DIMS 64

double st_ref_rng_uniform(st_ref_rng *r) {
    if (r->ld && r->dim < LD_DIMS) return ld_uniform(r);
    // 53 random bits, so triangle picks stay exact in meshes of many triangles.
    uint64_t hi = st_ref_rng_u32(r) >> 5, lo = st_ref_rng_u32(r) >> 6; // 27 + 26 bits
    return (double)((hi << 26) | lo) * (1.0 / 9007199254740992.0);
}

uint64_t st_ref_rng_hash(uint64_t a, uint64_t b) {
    return mix64(a ^ mix64(b + 0x9e3779b97f4a7c15ull));
}

// Low-discrepancy mode: pbrt-v4's padded Sobol sampler (Pharr et al.,
// Physically Based Rendering 4th ed., 8.7). Dimensions go in pairs
// (2k, 2k + 1); each pair is the (0, 2)-sequence of Sobol's first two
// dimensions over the batch's n points, Owen-scrambled per dimension and
// with the point order shuffled per pair, so pairs are independent of each
// other while each pair's n points stratify its square. For a fixed index
// every dimension's value is uniform and independent of the others (the
// scrambles are), so any estimator that was unbiased with independent
// numbers stays unbiased, whatever dimensions a path consumes.

// Kensler's hashed permutation of [0, l) (Correlated Multi-Jittered
// Sampling, 2013): a bijection for any l, cycle-walking inside the next
// power of two.
static uint32_t permute(uint32_t i, uint32_t l, uint32_t p) {
    uint32_t w = l - 1;
    w |= w >> 1, w |= w >> 2, w |= w >> 4, w |= w >> 8, w |= w >> 16;
    do {
        i ^= p, i *= 0xe170893d, i ^= p >> 16, i ^= (i & w) >> 4;
        i ^= p >> 8, i *= 0x0929eb3f, i ^= p >> 23, i ^= (i & w) >> 1;
        i *= 1 | p >> 27, i *= 0x6935fa69, i ^= (i & w) >> 11, i *= 0x74dcb303;
        i ^= (i & w) >> 2, i *= 0x9e501cc3, i ^= (i & w) >> 2, i *= 0xc860a3df;
        i &= w, i ^= i >> 5;
    } while (i >= l);
    return (i + p) % l;
}

static uint32_t reverse_bits(uint32_t v) {
    v = ((v >> 1) & 0x55555555u) | ((v & 0x55555555u) << 1);
    v = ((v >> 2) & 0x33333333u) | ((v & 0x33333333u) << 2);
    v = ((v >> 4) & 0x0f0f0f0fu) | ((v & 0x0f0f0f0fu) << 4);
    v = ((v >> 8) & 0x00ff00ffu) | ((v & 0x00ff00ffu) << 8);
    return (v >> 16) | (v << 16);
}

// Sobol's first dimension (van der Corput) or second, as 32-bit fractions.
static uint32_t sobol(uint32_t i, int second) {
    if (!second) return reverse_bits(i);
    uint32_t v = 1u << 31, x = 0;
    for (; i; i >>= 1, v ^= v >> 1)
        if (i & 1) x ^= v;
    return x;
}

// Owen scrambling by the hash of Laine and Karras as improved by Vegdahl
// (pbrt-v4's FastOwenScrambler): each bit flips by a hash of the bits above it.
static uint32_t owen(uint32_t v, uint32_t seed) {
    v = reverse_bits(v);
    v ^= v * 0x3d20adeau;
    v += seed;
    v *= (seed >> 16) | 1u;
    v ^= v * 0x05526c56u;
    v ^= v * 0x53a22864u;
    return reverse_bits(v);
}

void st_ref_rng_start_sample(st_ref_rng *r, uint64_t key, uint32_t index, uint32_t n) {
    r->key = key, r->index = index, r->n = n > 0 ? n : 1, r->dim = 0, r->ld = true;
}

static double ld_uniform(st_ref_rng *r) {
    const uint32_t dim = r->dim++;
    if (!(dim & 1)) { // a new pair: its shuffle and scrambles, hashed once for both dimensions
        const uint64_t pair = st_ref_rng_hash(r->key, dim >> 1);
        r->pair_index = permute(r->index, r->n, (uint32_t)(pair >> 32));
        r->scrambles = mix64(pair);
    }
    const uint32_t seed = (uint32_t)(r->scrambles >> (dim & 1 ? 32 : 0));
    const uint32_t x = owen(sobol(r->pair_index, (int)(dim & 1)), seed);
    // 32 scrambled bits, 21 random ones below them: 53 bits like the PCG path.
    uint64_t low = st_ref_rng_u32(r) >> 11;
    return (double)(((uint64_t)x << 21) | low) * (1.0 / 9007199254740992.0);
}
