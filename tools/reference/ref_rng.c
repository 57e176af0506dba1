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
    r->state = 0;
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

double st_ref_rng_uniform(st_ref_rng *r) {
    // 53 random bits, so triangle picks stay exact in meshes of many triangles.
    uint64_t hi = st_ref_rng_u32(r) >> 5, lo = st_ref_rng_u32(r) >> 6; // 27 + 26 bits
    return (double)((hi << 26) | lo) * (1.0 / 9007199254740992.0);
}
