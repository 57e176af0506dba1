// toth: the visible fraction of each light's in-scattering along a view ray,
// with the march samples placed in the equi-angular parametrization (see
// equiangular.glsl) by the integrand (toth_cdf below). Light l's share of
// the unshadowed integral is weighted by the smooth angular integrand, so
// the fraction sum(w V) / sum(w) is exact for a fully lit or fully shadowed
// ray at any sample count and the samples crowd where the light contributes
// most. Lights 0..2 get a channel each; lights 3.. share
// the fourth (exact when they see the same occluders).
//
// Each step looks up the shadow map at both ends. Where the two disagree
// (a shadow boundary inside the step) `bisect` halvings locate the boundary,
// so the lit part of the step is known to step / 2^(bisect + 1) instead of
// step / 2: K + 1 + bisect x (boundaries) lookups resolve what K x 2^bisect
// uniform steps would. Where they agree the step counts as wholly lit or
// shadowed (an occluder thinner than a step between two lookups is missed,
// as it is by a march of the same step).
#ifndef TOTH_VISIBILITY_GLSL
#define TOTH_VISIBILITY_GLSL
#include "toth/equiangular.glsl"
#include "shadow_map/visibility.glsl"

float toth_vis_at(int l, toth_eq e, vec3 o, vec3 dir, float delta) {
    float t, d;
    toth_eq_point(e, delta, t, d);
    return st_visibility_point(l, o + t * dir);
}

// exact_edges: a boundary the shadow map brackets inside a step is settled
// with exact rays against shadow_map.refine's BVH (common/bvh.glsl) instead.
uniform int toth_exact;

bool toth_exact_on() { return toth_exact != 0 && st_shadow_refine != 0; }

// The end of light l's exact ray from x: the light, or a sun's entry plane.
vec3 toth_exact_target(int l, vec3 x) {
    if (!ST_LIGHT_IS(l, 1)) return st_light_pos[l];
    vec3 L = -st_light_dir[l];
    return x + L * max(st_light_shape[l].z - dot(x, L), 1e-3);
}

// Exact visibility of light l from the ray point at angle delta: the
// triangle that blocks the segment to the light (a sun: to its entry
// plane), the first the traversal meets; -1: none, the point is lit.
int toth_exact_tri(int l, toth_eq e, vec3 o, vec3 dir, float delta) {
    float t, d;
    toth_eq_point(e, delta, t, d);
    vec3 x = o + t * dir;
    return st_bvh_occluder(x, toth_exact_target(l, x), 1e-6);
}

float toth_exact_at(int l, toth_eq e, vec3 o, vec3 dir, float delta) {
    return toth_exact_tri(l, e, o, dir, delta) >= 0 ? 0.0 : 1.0;
}

// The last two exact lookups of toth_vis_exact_or_map (light, angle, the
// blocking triangle or -1): a step's shadow walk and a boundary's search
// start from a step end that was often traced already (-2: not here).
int toth_memo_l[2] = int[2](-1, -1), toth_memo_t[2] = int[2](-2, -2);
float toth_memo_d[2] = float[2](0.0, 0.0);

int toth_memo(int l, float delta) {
    for (int k = 0; k < 2; k++)
        if (toth_memo_l[k] == l && toth_memo_d[k] == delta) return toth_memo_t[k];
    return -2;
}

// exact_edges: the map's verdict at the ray point at angle delta, taken
// only where the map can decide it. `amb`: undecided in shadow_map.refine's
// sense for a point without a normal (one of 8 taps two texels around it
// disagrees, the point is lit only thanks to the bias, or a sun's point
// lies outside every cascade); such a lookup takes the exact ray instead.
// A misplaced edge is a fraction of a texel off, so only lookups near an
// edge pay for a ray.
float toth_vis_exact_or_map(int l, toth_eq e, vec3 o, vec3 dir, float delta, out bool amb) {
    float t, d;
    toth_eq_point(e, delta, t, d);
    vec3 x = o + t * dir;
    float v = 1.0;
    amb = false;
    if (ST_LIGHT_IS(l, 1)) {
        v = st_shadow_sun_amb(l, x, st_shadow_bias, 0.0, true, amb);
    } else if (ST_LIGHT_POSITIONED(l)) {
        float bias = st_shadow_texel(distance(x, st_light_pos[l])) * st_shadow_bias;
        v = st_shadow_visibility_amb(l, x, bias, 0.0, true, amb);
    }
    for (int once = 0; once < (amb ? 1 : 0); once++) {
        int t = toth_exact_tri(l, e, o, dir, delta);
        toth_memo_l[1] = toth_memo_l[0], toth_memo_d[1] = toth_memo_d[0], toth_memo_t[1] = toth_memo_t[0];
        toth_memo_l[0] = l, toth_memo_d[0] = delta, toth_memo_t[0] = t;
        v = t >= 0 ? 0.0 : 1.0;
    }
    return v;
}

// The lit part of the step [a, b] whose visibility changes at x (lit_first:
// lit on [a, x], else on [x, b]), weighted by the lit sub-interval's own
// midpoint: the integrand varies across a step, most where the phase
// function peaks.
vec3 toth_lit_part(toth_eq e, float a, float b, float x, bool lit_first, vec3 sig) {
    float la = lit_first ? a : x, lb = lit_first ? x : b;
    return lb > la ? toth_eq_integrand(e, 0.5 * (la + lb), sig) * (lb - la) : vec3(0.0);
}

// The stretch [x, y] of the view ray o + t dir that triangle i shadows from
// light l (x > y: none): the ray's intersection with the triangle's shadow
// volume, the convex region bounded by the triangle's plane (on the side
// away from the light) and by the three planes through each edge and the
// light (a sun: each edge and its direction).
vec2 toth_tri_shadow(int l, int i, vec3 o, vec3 dir) {
    vec3 v[3], e1, e2;
    st_bvh_triangle(i, v[0], e1, e2);
    v[1] = v[0] + e1;
    v[2] = v[0] + e2;
    bool sun = ST_LIGHT_IS(l, 1);
    vec3 L = -st_light_dir[l], P = st_light_pos[l];
    vec2 r = vec2(-3.0e38, 3.0e38);
    for (int k = 0; k < 4; k++) {
        // The half-space dot(m, x - base) >= 0 as f0 + f1 t >= 0.
        vec3 m, base;
        float side;
        if (k < 3) {
            vec3 p = v[k], q = v[(k + 1) % 3];
            base = sun ? p : P;
            m = sun ? cross(q - p, L) : cross(p - P, q - P);
            side = dot(m, v[(k + 2) % 3] - base); // the third vertex is inside
        } else {
            base = v[0];
            m = cross(e1, e2);
            side = -(sun ? dot(m, L) : dot(m, P - v[0])); // behind the triangle
        }
        if (side == 0.0) return vec2(1.0, 0.0); // seen edge-on: no volume
        m *= sign(side);
        float f0 = dot(m, o - base), f1 = dot(m, dir);
        if (f1 == 0.0) {
            if (f0 < 0.0) return vec2(1.0, 0.0);
        } else if (f1 > 0.0) {
            r.x = max(r.x, -f0 / f1);
        } else {
            r.y = min(r.y, -f0 / f1);
        }
    }
    return r;
}

// Where triangle i's shadow on the ray ends, as an angle: the exit toward
// larger angles, or toward smaller ones (backward: the entry). `hit` false
// where the ray misses the shadow volume.
float toth_tri_shadow_end(int l, int i, toth_eq e, vec3 o, vec3 dir, bool backward, out bool hit) {
    vec2 r = toth_tri_shadow(l, i, o, dir);
    hit = r.x <= r.y;
    return toth_eq_angle(e, backward ? r.x : r.y);
}

// exact_edges: the lit part of [a, b] between exact ends va != vb (one lit,
// one shadowed). The shadowed end's exact ray names the triangle that
// blocks it (tri, when the caller traced it already; -2: not yet); that
// triangle's shadow along the view ray ends in closed form
// (toth_tri_shadow), and one ray just past that end on the lit side checks
// that nothing continues the shadow there. If something does (the next
// triangle of the same mesh), its own shadow is taken from that point. Once
// lit, one ray halfway to the lit end checks the rest of the step (the old
// bisection's first halving looked there too): lit, the boundary is found;
// shadowed (a second occluder inside the step), the search goes on from
// there, and the lit sliver before it is dropped. (toth_vis_probed splits a
// step whose ends disagree at its probes first where these see a second
// boundary.) After TOTH_EXACT_TRIES
// triangles, or for an end outside the bracket (float rounding at a
// vertex), the rest of the bracket is bisected n times with exact rays as
// before. A boundary costs ~3 rays instead of n and lies where the geometry
// puts it to float precision, not to (b - a) / 2^(n + 1). One loop with one
// ray per turn: llvmpipe runs a shader's lanes in lock-step, so lanes at
// different stages then share each traversal instead of taking turns.
#define TOTH_EXACT_TRIES 8
// A point inside the step that the map's probes call shadowed, on the lit
// side of the search's first boundary (toth_vis_probed; -1: none): the
// check after the first boundary traces it instead of the midpoint.
// godrays_window's top wall and mullion cast shadows that meet with a
// hairline gap between them: the ray just past the wall's shadow and the
// midpoint were both lit, and the mullion's shadow in between was lost (4%
// of a pixel's light).
float toth_hint = -1.0;
uniform int toth_exact_solve = 1; // 0: bisection only, as before (toth.exact_solve)
vec3 toth_exact_boundary(int l, toth_eq e, vec3 o, vec3 dir, float a, float b, float va, int n, int tri,
                         vec3 sig) {
    bool lit_first = va > 0.5;
    float sh = lit_first ? b : a, li = lit_first ? a : b; // shadowed and lit ends
    float nudge = 1e-4 * (b - a), x = sh, lo = sh, hi = li;
    // stage 0: trace the shadowed end (unless its lookup did: toth_memo);
    // 1: a triangle blocks sh, trace just past its shadow's end x; 2: lit
    // there, trace halfway to li; 3: bisect; 4: done, the boundary at x.
    // (Work that only some lanes need sits in loops run once: see
    // toth_vis_step_exact.)
    if (tri < -1) tri = toth_memo(l, sh);
    int stage = toth_exact_solve == 0 ? 3 : tri < -1 ? 0 : tri < 0 ? 4 : 1, tries = 0, halvings = 0;
    bool hinted = false; // toth_hint traced
    for (int it = 0; it < TOTH_EXACT_TRIES * 2 + 3 + n && stage < 4; it++) {
        for (int once = 0; once < (stage == 1 ? 1 : 0); once++) {
            bool ok = tries < TOTH_EXACT_TRIES;
            tries++;
            bool hit;
            x = toth_tri_shadow_end(l, tri, e, o, dir, lit_first, hit);
            ok = ok && hit && (lit_first ? x > li && x < sh : x > sh && x < li);
            if (!ok) stage = 3, lo = sh, hi = li;
        }
        if (stage == 3 && halvings >= n) {
            x = 0.5 * (lo + hi), stage = 4;
            break;
        }
        bool hint = stage == 2 && !hinted && (lit_first ? toth_hint < x && toth_hint > li : toth_hint > x && toth_hint < li);
        float q = stage == 0 ? sh : stage == 1 ? (lit_first ? x - nudge : x + nudge)
                              : stage == 2 ? (hint ? toth_hint : 0.5 * (x + (hinted ? toth_hint : li)))
                                           : 0.5 * (lo + hi);
        // (One ray per turn for every stage: the map's 9 taps halfway to li
        // would cost every lane in the loop.)
        int t = toth_exact_tri(l, e, o, dir, q);
        if (stage == 0) {
            // The map called the end shadowed, the exact ray sees it lit: the
            // whole step is lit (x = sh: where bisection converges).
            if (t < 0) stage = 4;
            else tri = t, stage = 1;
        } else if (stage == 1) {
            if (t < 0) {
                stage = 2;
            } else { // shadowed too: a boundary lies beyond q
                sh = q;
                // The same triangle still: float rounding at its edge, a
                // longer nudge next time.
                if (t == tri) nudge *= 8.0;
                tri = t;
            }
        } else if (stage == 2) {
            // The hint lit too (the map was wrong there): the midpoint next.
            if (t < 0) stage = hint ? 2 : 4;
            else sh = q, tri = t, stage = 1;
            hinted = hinted || hint;
        } else {
            if (t >= 0) lo = q;
            else hi = q;
            halvings++;
        }
    }
    if (stage != 4) x = 0.5 * (lo + hi); // (not reached: the trip count covers every stage)
    return toth_lit_part(e, a, b, x, lit_first, sig);
}

// exact_edges: the lit part of the step [a, b] whose ends see va and vb
// (exact where the map could not decide; amb_a, amb_b: they were
// undecided). Ends that disagree bracket a boundary, settled by exact
// bisection. Ends that agree but lie near an edge (undecided) may hide a
// sliver of the other kind between them, which the map's lookups at the
// ends cannot bracket (hidden_hole's shaft grazed by a view ray): shadowed
// ends walk the shadows from a (the blocking triangle's shadow ends in
// closed form, toth_tri_shadow; one ray just past it names the next) until
// a lit point or past b (the step is covered: no sliver), lit ends (or a
// walk that stops) trace the step's midpoint, and a point that disagrees
// splits the step into two bracketed halves. The midpoint alone missed a
// lit stretch between two shadows whenever it fell into the second one
// (godrays_window's mullions; test_toth_slivers).
vec3 toth_vis_step_exact(int l, toth_eq e, vec3 o, vec3 dir, float a, float b, float va, float vb, bool amb_a,
                         bool amb_b, int bisect, vec3 w, vec3 sig) {
    int n = bisect + 4;
    // Ends that agree but are undecided, or a clean on/off boundary (not
    // PCF's soft one, which keeps the trapezoid) take the exact search.
    bool agree = va == vb;
    bool search = bisect > 0 && (agree ? amb_a || amb_b : abs(va - vb) >= 0.5);
    vec3 lit = w * 0.5 * (va + vb);
    // A loop run once, not an if: llvmpipe runs an if's body for every lane
    // (masked), but leaves a loop as soon as no lane is in it.
    for (int once = 0; once < (search ? 1 : 0); once++) {
        // Ends that agree: the midpoint m, and a boundary in each half if
        // it disagrees (a shadowed midpoint is the shadowed end of both).
        // Ends that disagree: one boundary in [a, b]. One call of
        // toth_exact_boundary for all: see there.
        float m = b, vm = vb;
        int tm = -2, halves = 1;
        if (agree) {
            m = 0.5 * (a + b);
            // Shadowed ends: walk the shadows from a (each blocking
            // triangle's shadow ends in closed form, one ray just past it
            // says what follows) to the first lit point, or prove the step
            // covered. Lit ends, or a walk that cannot go on: the midpoint.
            // stage 0: trace a; 1: trace just past the shadow's end pos; 2:
            // trace the midpoint; 3: done. One ray per turn (see
            // toth_exact_boundary).
            int stage = va < 0.5 && toth_exact_solve != 0 ? 0 : 2, ts = -1;
            float nudge = 1e-4 * (b - a), pos = a;
            vm = va;
            for (int it = 0; it < TOTH_EXACT_TRIES + 2 && stage < 3; it++) {
                float q = stage == 0 ? a : stage == 1 ? pos + nudge : m;
                int t = stage == 0 ? toth_memo(l, a) : -2;
                for (int once = 0; once < (t < -1 ? 1 : 0); once++) t = toth_exact_tri(l, e, o, dir, q);
                if (stage == 2) {
                    tm = t, vm = t >= 0 ? 0.0 : 1.0, stage = 3;
                } else if (t < 0) {
                    // a lit after all (the map decided it): the midpoint.
                    if (stage == 0) stage = 2;
                    else m = q, vm = 1.0, stage = 3;
                } else if (stage == 1 && t == ts) {
                    nudge *= 8.0; // float rounding at the triangle's edge
                } else {
                    ts = t;
                    bool hit;
                    float x = toth_tri_shadow_end(l, t, e, o, dir, false, hit);
                    if (!hit || !(x > pos) || it >= TOTH_EXACT_TRIES) stage = 2;
                    else if (x >= b) stage = 3; // covered: no sliver
                    else pos = x, stage = 1;
                }
            }
            halves = vm == va ? 0 : 2;
            n -= 1;
        }
        vec3 part = w * va;
        if (halves > 0) part = vec3(0.0);
        for (int h = 0; h < halves; h++)
            part += toth_exact_boundary(l, e, o, dir, h == 0 ? a : m, h == 0 ? m : b, h == 0 ? va : vm, n,
                                        tm >= 0 ? tm : -2, sig);
        lit = part;
    }
    return lit;
}

// The lit part of the step [a, b] whose ends see va and vb, weighted by
// the integrand (per channel: sig is sigma_t, or its grey mean): where a
// boundary is located inside the step, the lit sub-interval's own midpoint
// weighs it (the integrand varies across a step, most where the phase
// function peaks); otherwise the step's weight w. x: the boundary located
// (-1: none).
vec3 toth_vis_step(int l, toth_eq e, vec3 o, vec3 dir, float a, float b, float va, float vb, int bisect,
                   vec3 w, vec3 sig, out float x) {
    x = -1.0;
    if (va == vb) return w * va;
    // Not a clean on/off boundary (PCF): the trapezoid.
    if (abs(va - vb) < 0.5 || bisect <= 0) return w * 0.5 * (va + vb);
    float lo = a, hi = b;
    for (int k = 0; k < bisect; k++) {
        float m = 0.5 * (lo + hi);
        float vm = toth_vis_at(l, e, o, dir, m);
        if (abs(vm - va) < abs(vm - vb)) lo = m;
        else hi = m;
    }
    x = 0.5 * (lo + hi);
    return toth_lit_part(e, a, b, x, va > vb, sig);
}

// A lookup at the ray point at angle delta: the map's (exact: settled by
// a ray where the map is undecided, see toth_vis_exact_or_map).
float toth_vis_lookup(bool exact, int l, toth_eq e, vec3 o, vec3 dir, float delta, out bool amb) {
    amb = false;
    return exact ? toth_vis_exact_or_map(l, e, o, dir, delta, amb) : toth_vis_at(l, e, o, dir, delta);
}

vec3 toth_vis_step_any(bool exact, int l, toth_eq e, vec3 o, vec3 dir, float a, float b, float va, float vb,
                       bool amb_a, bool amb_b, int bisect, vec3 w, vec3 sig) {
    if (exact) return toth_vis_step_exact(l, e, o, dir, a, b, va, vb, amb_a, amb_b, bisect, w, sig);
    float x;
    return toth_vis_step(l, e, o, dir, a, b, va, vb, bisect, w, sig, x);
}

// probes: where a step's two ends agree, `toth_probes` more map lookups at
// equal spacing inside it look for an occluder or a lit sliver between
// them (a view ray grazing a shaft: the lit stretch can be far shorter than
// a step, hidden_hole's shaft edges). Probes cost a map lookup each; only
// a step whose probes disagree with its ends is split at them, and each
// piece is then settled as a step of its own (its boundary bisected). A
// step whose ends disagree is split where its probes change more than once
// (see below).
uniform int toth_probes;

vec3 toth_vis_probed(bool exact, int l, toth_eq e, vec3 o, vec3 dir, float a, float b, float va, float vb,
                     bool amb_a, bool amb_b, int bisect, vec3 w, vec3 sig) {
    int P = toth_probes;
    float h = (b - a) / float(P + 1);
    // Ends that disagree are split at the probes too where these see a
    // second boundary (their verdicts change more than once): one boundary
    // search per step finds one of them (godrays_window at 24 steps: 3-4%
    // of a pixel's light lost where the jittered step grid put a lit gap
    // and a mullion's shadow into one step). Splitting every such step
    // would also catch a shadow that begins right after the one ending in
    // the step (4.1e-5 -> 2.1e-5 rmse there), but its pieces' lookups near
    // the boundary take ~37% more exact rays (hidden_hole's edges pass 1.2x
    // the time).
    int changes = 0, k0 = 0;
    float pv = va;
    for (int k = 1; k <= P + 1 && changes < (va != vb ? 2 : 1); k++) {
        float v = k <= P ? toth_vis_at(l, e, o, dir, a + h * float(k)) : vb;
        if (v != pv && changes++ == 0) k0 = k;
        pv = v;
    }
    bool split = P > 0 && changes >= (va != vb ? 2 : 1);
    // One change (between probes k0 - 1 and k0): the probe next to it on
    // the shadowed side is the boundary search's check (toth_hint).
    int kh = va < vb ? k0 - 1 : k0;
    toth_hint = !split && va != vb && kh >= 1 && kh <= P ? a + h * float(kh) : -1.0;
    // The step, or its pieces, settled by one call in a loop (llvmpipe runs
    // the lanes of a shader in lock-step: each call site costs every lane).
    int pieces = split ? P + 1 : 1;
    vec3 lit = vec3(0.0);
    float sa = a, sv = va;
    bool samb = amb_a;
    for (int k = 1; k <= pieces; k++) {
        float sb = k == pieces ? b : a + h * float(k);
        bool bamb = amb_b;
        float bv = k == pieces ? vb : toth_vis_lookup(exact, l, e, o, dir, sb, bamb);
        vec3 wk = pieces == 1 ? w : toth_eq_integrand(e, 0.5 * (sa + sb), sig) * (sb - sa);
        lit += toth_vis_step_any(exact, l, e, o, dir, sa, sb, sv, bv, samb, bamb, bisect, wk, sig);
        sa = sb, sv = bv, samb = bamb;
    }
    toth_hint = -1.0;
    return lit;
}

// Where the steps go: equal shares of a density in theta that is half
// uniform and half the unshadowed integrand (phase function, extinction,
// spot falloff) tabulated at TOTH_CDF_CELLS cell midpoints, so the lookups
// crowd where the light scatters most toward the camera (a forward-peaked
// phase function puts most of a ray's light on a short stretch of it) and
// still cover the rest. toth_cdf_at maps a share y in [0, 1] to theta.
#define TOTH_CDF_CELLS 16
struct toth_cdf {
    float c[TOTH_CDF_CELLS + 1];
    float len;
};

toth_cdf toth_cdf_build(toth_eq e, vec3 grey) {
    toth_cdf d;
    d.len = e.len;
    float cell = e.len / float(TOTH_CDF_CELLS), total = 0.0;
    float q[TOTH_CDF_CELLS];
    for (int k = 0; k < TOTH_CDF_CELLS; k++) {
        q[k] = toth_eq_integrand(e, (float(k) + 0.5) * cell, grey).x;
        total += q[k];
    }
    d.c[0] = 0.0;
    for (int k = 0; k < TOTH_CDF_CELLS; k++) {
        float share = total > 0.0 ? q[k] / total : 1.0 / float(TOTH_CDF_CELLS);
        d.c[k + 1] = d.c[k] + 0.75 * share + 0.25 / float(TOTH_CDF_CELLS);
    }
    d.c[TOTH_CDF_CELLS] = 1.0;
    return d;
}

// k: the cell to start the search from (shares are asked in increasing order).
float toth_cdf_at(toth_cdf d, float y, inout int k) {
    if (y <= 0.0) return 0.0;
    if (y >= 1.0) return d.len;
    while (k < TOTH_CDF_CELLS - 1 && y >= d.c[k + 1]) k++;
    float span = d.c[k + 1] - d.c[k];
    float f = span > 0.0 ? clamp((y - d.c[k]) / span, 0.0, 1.0) : 0.0;
    return (float(k) + f) * d.len / float(TOTH_CDF_CELLS);
}

// Steps first, first + stride, ... < n of n steps with equal shares of that
// density; the grid is shifted by u in [0, 1) of a share (the first and last
// steps are shortened to stay in [0, len]). Returns the fraction per channel
// (1 where a light adds nothing, so the full-resolution product stays exact).
// One light: its fraction per colour channel in rgb (w = 1), each weighted by
// that channel's integrand: with sigma_t differing by colour, the lit part
// nearer the camera weighs more in the channel that is extinguished faster
// (grey weights put godrays_window's red and blue 0.6% off where a view ray
// crosses the shaft, 1.5e-4 rmse at 1024 steps against 4.6e-5 in green).
// More lights: one grey fraction each (lights 3.. share the fourth).
bool toth_rgb_fraction() { return st_num_lights == 1; }

vec4 toth_visible_fraction(vec3 o, vec3 dir, float s, int n, int first, int stride, float u, int bisect,
                           vec3 sigma_t) {
    n = max(n, 1);
    stride = max(stride, 1);
    // The steps' placement: one density for all channels (visibility is
    // grey; the channels' extinctions differ little).
    vec3 grey = vec3((sigma_t.x + sigma_t.y + sigma_t.z) / 3.0);
    bool rgb = toth_rgb_fraction();
    vec3 sig = rgb ? sigma_t : grey;
    vec4 num = vec4(0.0), den = vec4(0.0);
    bool exact = toth_exact_on();
    for (int l = 0; l < st_num_lights; l++) {
        toth_eq e = toth_light_frame(o, dir, s, l);
        if (!(e.len > 0.0)) continue;
        toth_memo_l[0] = toth_memo_l[1] = -1; // angles of another ray's frame
        toth_cdf cdf = toth_cdf_build(e, grey);
        int ka = 0, kb = 0;
        int c = min(l, 3);
        // Steps i = 0..n: shares [(i - 1 + u) / n, (i + u) / n].
        float prev_b = -1.0, vprev = 0.0;
        bool aprev = false;
        for (int i = first; i <= n; i += stride) {
            float a = toth_cdf_at(cdf, (float(i) - 1.0 + u) / float(n), ka);
            float b = toth_cdf_at(cdf, (float(i) + u) / float(n), kb);
            if (!(b > a)) continue;
            vec3 w = toth_eq_integrand(e, 0.5 * (a + b), sig) * (b - a);
            if (!(w.x > 0.0)) continue;
            bool amb_a = a == prev_b ? aprev : false, amb_b = false;
            float va = a == prev_b ? vprev : toth_vis_lookup(exact, l, e, o, dir, a, amb_a);
            float vb = toth_vis_lookup(exact, l, e, o, dir, b, amb_b);
            vec3 lit = toth_vis_probed(exact, l, e, o, dir, a, b, va, vb, amb_a, amb_b, bisect, w, sig);
            aprev = amb_b;
            if (rgb) {
                num.xyz += lit;
                den.xyz += w;
            } else {
                num[c] += lit.x;
                den[c] += w.x;
            }
            prev_b = b;
            vprev = vb;
        }
    }
    vec4 f;
    for (int c = 0; c < 4; c++) f[c] = den[c] > 0.0 ? clamp(num[c] / den[c], 0.0, 1.0) : 1.0;
    return f;
}
#endif
