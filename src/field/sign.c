/*
 * sign.c - volume-event voting (see sign.h; Spillmann et al. 2006, §3).
 * Design notes and measurements: doc/design/sign.md.
 *
 * Per direction, two streaming passes over the grid:
 *   1. walk every line, find its event runs (voxels with |d| < t), count
 *      them (E, per line, mod 2) and mark in the voxel's byte where the
 *      forward ray toggles (S) and where the backward ray toggles (R);
 *   2. walk again, counting marks: the forward ray's parity at v is the
 *      number of S at or before v, the backward ray's is the number of R at
 *      or after v, which is E minus the R strictly before v; add the votes.
 * So 26 rays cost two passes per line, the same as 26 plain passes; pass 2
 * reads only the byte per voxel, not the field.
 *
 * Memory: the field plus ONE BYTE PER VOXEL for every rule (votes, the
 * union rule's "seen from outside" bit and the current direction's two
 * marks; see "the byte per voxel" below), plus per-thread line states
 * (a few hundred kilobytes, not per voxel).
 *
 * Speed: far from the surface nothing changes along a line, so pass 1 only
 * tests 32 voxels at a time for events (a vector compare) and pass 2 adds
 * each line's constant addition branch-free; the per-event work (walking
 * a run, placing its marks) is done only where there are events.
 *
 * Memory order. The four directions within a z layer are walked line by
 * line, a layer at a time (a layer stays in cache); layers are independent
 * and run in parallel. The nine directions that cross layers keep one state
 * per line and stream layer after layer, each layer read in storage order,
 * a block of consecutive rows per thread (every voxel of a row is on a
 * different line).
 */
#include "souptet/sign.h"
#include "../base/fpenv.h"
#include "souptet/mem.h"
#include "souptet/bvh.h"
#include "souptet/isect.h"
#include "souptet/pred.h"
#include "souptet/mincut.h"
#include "../base/bits.h"

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

/* The 13 lines of the 26-neighbourhood, each walked so that it moves
 * forward in memory; the first four stay in a layer. */
static const int DIRS[13][3] = {
    {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {-1, 1, 0},
    {0, 0, 1}, {1, 0, 1}, {-1, 0, 1}, {0, 1, 1}, {0, -1, 1},
    {1, 1, 1}, {-1, 1, 1}, {1, -1, 1}, {-1, -1, 1}};
#define IN_LAYER 4

st_sign_params st_sign_params_paper(void)
{
    st_sign_params p = {0.8, 0.0, 26, ST_TOGGLE_FIRST, 0, 0, 0, 0};
    return p;
}

st_sign_params st_sign_params_default(void)
{
    /* Chosen by the accuracy benchmark (make bench STAGE=accuracy; the
     * figures are in doc/design/sign.md):
     *   - the crossing toggle: both rays of a line agree on which side of
     *     the surface every voxel is, and a line with an odd number of
     *     events gives every voxel one inside and one outside vote, so it
     *     is neutral without being dropped;
     *   - the event distance of k = 1, half a step along each direction:
     *     the least that catches every crossing (a sample lies within half
     *     a step of it), where k = 0.8 on a band field (0.6 voxel) misses
     *     crossings of the diagonal rays, whose steps are 1.41 and 1.73
     *     voxels, and a missed crossing breaks the union below;
     *   - the union of hidden parts, for interpenetrating shells;
     *   - split event runs: two crossings closer than the event distance
     *     (where interpenetrating shells meet, across thin walls and
     *     tunnels) are two events, not one;
     *   - the cut of the undecided voxels (mincut.h): the votes as
     *     evidence, the surface as a cheap place to cut.
     * Nothing here depends on how far the grid reaches (c is not used at
     * k = 1), so a narrow-band field suffices. */
    st_sign_params p = {1.0, 0.0, 26, ST_TOGGLE_CROSSING, 0, 1, 1, 1};
    return p;
}

int st_sign_params_named(st_sign_params *p, const char *name)
{
    if (strcmp(name, "paper") == 0)
        *p = st_sign_params_paper();
    else if (strcmp(name, "default") == 0)
        *p = st_sign_params_default();
    else if (strcmp(name, "parity") == 0) {
        *p = st_sign_params_paper();
        p->k = 1.0;
    } else
        return -1;
    return 0;
}

/* At k = 1 a crossing shows as a sample within half a step of the
 * surface, half a step included: a surface exactly halfway between two
 * samples (CAD faces on a grid's half-voxel planes) is within it. The
 * events are `d < t`, and d is a float rounded from an exact distance, so
 * t is half a step widened by a few float ulps (2^-20 relative, about 8
 * ulps): no crossing is missed for rounding, and nothing farther than
 * half a step plus a millionth of it becomes an event. */
#define HALF_STEP_SLACK (1.0 / 1048576.0)

double st_sign_event_distance(const st_sign_params *p, const st_grid *g)
{
    if (p->k >= 1.0)
        return 0.5 * g->voxel * (1.0 + HALF_STEP_SLACK);
    double range;
    if (p->band_voxels > 0)
        range = p->band_voxels * g->voxel;
    else {
        double mx = 0.0;
        size_t n = st_grid_count(g);
        #pragma omp parallel for reduction(max : mx) schedule(static)
        for (size_t i = 0; i < n; i++) {
            double a = fabs((double)g->data[i]);
            if (a > mx)
                mx = a;
        }
        range = mx;
    }
    return (1.0 - p->k) * range;
}

/* --- the byte per voxel ------------------------------------------------- */

/* Everything the sweep keeps per voxel is one byte (sweep.v):
 *   bits 0-4  U, the vote count, 0..26: each of the 13 lines adds 0, 1 or
 *             2 (with 26 rays its two rays' inside votes; with 13 rays
 *             twice its one vote; a line dropped for odd parity adds 1,
 *             neutral), so the voxel is inside by majority exactly when
 *             U > 13 (ties outside; see vote_inside);
 *   bit 5     VISIBLE: some ray reaches the voxel from outside without
 *             meeting an event. The union rule's "hidden along all rays"
 *             is its complement, so one OR-accumulated bit replaces a
 *             count of hidden rays;
 *   bit 6, 7  the marks of the direction being swept: its forward ray
 *             toggles here (S) / its backward ray toggles here (R). Pass 1
 *             sets them, pass 2 of the same direction reads and clears
 *             them, so they are free again for the next direction.
 * U never exceeds 26 < 32, so adding to it never carries into bit 5. */
#define V_COUNT 0x1Fu
#define V_VISIBLE 0x20u
#define MARK_S 0x40u
#define MARK_R 0x80u
#define MARKS (MARK_S | MARK_R)

/* Is U (with 13 lines) a majority? u = sum of the lines' additions. */
static inline int vote_inside(unsigned u) { return u > 13; }

/* The state of one line in pass 2, a byte, chosen so that an unmarked
 * voxel's update is v = (v | (P & P_VIS)) + (P & P_ADD): P_ADD and P_VIS
 * are what the other bits imply (a table, sweep.tab), so the common case
 * is a few vector instructions per 16 voxels. Pass 1 uses only P_E_ODD. */
#define P_ADD 0x03u     /* what the line adds to U at this voxel */
#define P_E_ODD 0x04u   /* the line's number of events, mod 2 */
#define P_CS_ODD 0x08u  /* S marks at or before the voxel, mod 2 */
#define P_CR_ODD 0x10u  /* R marks strictly before the voxel, mod 2 */
#define P_VIS V_VISIBLE /* a ray of this line sees the voxel from outside */
#define P_SEEN 0x40u    /* an S mark at or before the voxel */
#define P_PAST 0x80u    /* past the line's last R mark */
#define P_STATE (P_E_ODD | P_CS_ODD | P_CR_ODD | P_SEEN | P_PAST)

#define NO_MARK SIZE_MAX

/* Split event runs: a rise of this fraction of the event distance between
 * two dips of the distance separates two crossings. */
#define SPLIT_RISE 0.2f

typedef struct sweep {
    const float *data;
    uint8_t *v;           /* the byte per voxel (above) */
    long nx, ny, nz;
    st_sign_toggle toggle;
    float t_axis;         /* event distance for an axis direction */
    int k1;               /* k = 1: the event distance scales with the step */
    int split;            /* split event runs at a rise between two dips */
    unsigned *count;      /* st_sign_line: counts the events (else NULL) */
    uint8_t tab[256];     /* P_STATE bits -> the full line state */
} sweep;

/* The line state the bits s (P_STATE) imply: the forward ray's vote is
 * CS, the backward ray's E ^ CR (R at or after the voxel = E minus R
 * before it); the forward ray is hidden from outside once it met an S,
 * the backward one until it passed the line's last R. */
static void sweep_table(sweep *w, const st_sign_params *p)
{
    for (unsigned s = 0; s < 256; s++) {
        if (s & ~P_STATE) {
            w->tab[s] = 0;
            continue;
        }
        unsigned fwd = (s & P_CS_ODD) != 0, back = ((s & P_E_ODD) != 0) ^ ((s & P_CR_ODD) != 0);
        unsigned add = p->rays == 26 ? fwd + back : 2 * fwd;
        if (p->ignore_odd && (s & P_E_ODD))
            add = 1;
        int hidden = (s & P_SEEN) && (p->rays == 13 || !(s & P_PAST));
        w->tab[s] = (uint8_t)(s | add | (hidden ? 0u : P_VIS));
    }
}

static inline float dir_event_distance(const sweep *w, const int d[3])
{
    /* At k = 1 the event distance is half of this direction's step. */
    if (w->k1) {
        int n = abs(d[0]) + abs(d[1]) + abs(d[2]);
        return w->t_axis * (float)sqrt((double)n);
    }
    return w->t_axis;
}

/* Bit q set where d[q] < t, q < n <= 32. The field has no negative value
 * (checked), so d < t is |d| < t. */
static inline uint32_t event_mask(const float *d, long n, float t)
{
#ifdef __SSE2__
    if (n == 32) {
        const __m128 tv = _mm_set1_ps(t);
        const __m128 c0 = _mm_cmplt_ps(_mm_loadu_ps(d), tv);
        const __m128 c1 = _mm_cmplt_ps(_mm_loadu_ps(d + 4), tv);
        const __m128 c2 = _mm_cmplt_ps(_mm_loadu_ps(d + 8), tv);
        const __m128 c3 = _mm_cmplt_ps(_mm_loadu_ps(d + 12), tv);
        const __m128 c4 = _mm_cmplt_ps(_mm_loadu_ps(d + 16), tv);
        const __m128 c5 = _mm_cmplt_ps(_mm_loadu_ps(d + 20), tv);
        const __m128 c6 = _mm_cmplt_ps(_mm_loadu_ps(d + 24), tv);
        const __m128 c7 = _mm_cmplt_ps(_mm_loadu_ps(d + 28), tv);
        const __m128 any = _mm_or_ps(_mm_or_ps(_mm_or_ps(c0, c1), _mm_or_ps(c2, c3)),
                                     _mm_or_ps(_mm_or_ps(c4, c5), _mm_or_ps(c6, c7)));
        if (!_mm_movemask_ps(any))
            return 0;               /* the usual case, far from the surface */
        return (uint32_t)_mm_movemask_ps(c0) | (uint32_t)_mm_movemask_ps(c1) << 4 |
               (uint32_t)_mm_movemask_ps(c2) << 8 | (uint32_t)_mm_movemask_ps(c3) << 12 |
               (uint32_t)_mm_movemask_ps(c4) << 16 | (uint32_t)_mm_movemask_ps(c5) << 20 |
               (uint32_t)_mm_movemask_ps(c6) << 24 | (uint32_t)_mm_movemask_ps(c7) << 28;
    }
#endif
    uint32_t m = 0;
    for (long q = 0; q < n; q++)
        m |= (uint32_t)(d[q] < t) << q;
    return m;
}

/* Bit q set where v[q] carries a mark, q < n <= 32. */
static inline uint32_t mark_mask(const uint8_t *v, long n)
{
#ifdef __SSE2__
    if (n == 32) {
        __m128i a = _mm_loadu_si128((const __m128i *)v);
        __m128i b = _mm_loadu_si128((const __m128i *)(v + 16));
        /* bit 6 to bit 7 (x + x), or'ed with bit 7: the byte's sign */
        a = _mm_or_si128(a, _mm_add_epi8(a, a));
        b = _mm_or_si128(b, _mm_add_epi8(b, b));
        return (uint32_t)_mm_movemask_epi8(a) | ((uint32_t)_mm_movemask_epi8(b) << 16);
    }
#endif
    uint32_t m = 0;
    for (long q = 0; q < n; q++)
        m |= (uint32_t)((v[q] & MARKS) != 0) << q;
    return m;
}

/* (m nonzero) */
static inline int ctz32(uint32_t m)
{
    return st_lowest_bit(m);
}

/* Steps a line through coordinate c (of n) can go forward / backward
 * along an axis it moves by dc (-1, 0, 1) before it leaves the grid. */
static inline long steps_fwd(long c, int dc, long n)
{
    return dc > 0 ? n - 1 - c : dc < 0 ? c : LONG_MAX;
}
static inline long steps_back(long c, int dc, long n)
{
    return steps_fwd(c, -dc, n);
}
static inline long lmin(long a, long b) { return a < b ? a : b; }

/* The crossing toggle's marks for an event whose nearest voxel is om
 * steps past idx (see walk_run). Along a line through a locally flat
 * surface the unsigned distance of the samples is |s - s0| sin(angle): a V
 * with its tip at the crossing s0, which lies within half a step of the
 * nearest sample m. The crossing is before m exactly when the previous
 * sample is nearer than the next (ties: before, so a voxel center on the
 * surface is past it both ways). The forward ray changes parity at the
 * first voxel past the crossing, the backward ray at the last voxel before
 * it: S at m and R at m - 1 when the crossing is before m, S at m + 1 and
 * R at m when it is after. Where m - 1 or m + 1 is off the line (the
 * surface touches the grid's border), the mark stays on m. */
static void place_marks(const sweep *w, ptrdiff_t stride, size_t idx, long bk, long fw,
                        long om, uint8_t *pl, size_t *lastr)
{
    const float *data = w->data + idx;
    const int has_prev = bk + om > 0, has_next = fw - om > 0;
    const ptrdiff_t m = om * stride;
    const float dp = has_prev ? data[m - stride] : INFINITY;
    const float dn = has_next ? data[m + stride] : INFINITY;
    ptrdiff_t s_at = m, r_at = m;
    if (dp <= dn) {
        if (has_prev)
            r_at = m - stride;
    } else if (has_next) {
        s_at = m + stride;
    }
    w->v[(ptrdiff_t)idx + s_at] |= MARK_S;
    w->v[(ptrdiff_t)idx + r_at] |= MARK_R;
    *pl ^= P_E_ODD;
    if (w->count)
        (*w->count)++;
    *lastr = (size_t)((ptrdiff_t)idx + r_at);
}

/* Pass 1. Voxel idx is an event and the voxel before it on the line is
 * not (or is off the grid): an event run starts here. The line has bk
 * voxels before idx and fw after it. Walk the run to its end (the voxels
 * after it are read now, from the layers ahead; their own turn in the
 * stream then sees an event before them and skips), place the marks of the
 * run's two rays, toggle the line's event parity (*pl) and note its latest
 * R mark (*lastr). */
static void walk_run(const sweep *w, ptrdiff_t stride, float t, size_t idx,
                     long bk, long fw, uint8_t *pl, size_t *lastr)
{
    const float *data = w->data + idx;
    long o = 0, om = 0;             /* offsets of the run's end and nearest */
    float mn = data[0];
    if (w->split) {
        /* Dips: a sample at least delta above the run's last minimum and
         * then one at least delta below that rise's maximum close an event
         * at the minimum and start another. */
        const float delta = SPLIT_RISE * t;
        float mx = mn;
        int rising = 0;
        while (o < fw) {
            const float a = data[(o + 1) * stride];
            if (!(a < t))
                break;
            o++;
            if (rising && a < mx - delta) {
                place_marks(w, stride, idx, bk, fw, om, pl, lastr);
                mn = mx = a;
                om = o;
                rising = 0;
                continue;
            }
            if (a < mn && !rising) {
                mn = a;
                om = o;
            }
            if (a > mn + delta)
                rising = 1;
            if (rising) {
                if (a > mx)
                    mx = a;
            } else
                mx = a;
        }
        place_marks(w, stride, idx, bk, fw, om, pl, lastr);
        return;
    }
    while (o < fw) {
        const float a = data[(o + 1) * stride];
        if (!(a < t))
            break;
        o++;
        if (a < mn) {               /* ties keep the first */
            mn = a;
            om = o;
        }
    }
    if (w->toggle == ST_TOGGLE_CROSSING) {
        place_marks(w, stride, idx, bk, fw, om, pl, lastr);
        return;
    }
    ptrdiff_t s_at, r_at;           /* offsets from idx */
    if (w->toggle == ST_TOGGLE_NEAREST) {
        s_at = r_at = om * stride;
    } else {
        s_at = 0;
        r_at = o * stride;
    }
    w->v[(ptrdiff_t)idx + s_at] |= MARK_S;
    w->v[(ptrdiff_t)idx + r_at] |= MARK_R;
    *pl ^= P_E_ODD;
    if (w->count)
        (*w->count)++;
    *lastr = (size_t)((ptrdiff_t)idx + r_at);
}

/* The events among row[i0 .. nx), 32 at a time (the last 32 overlap the
 * ones before; bits already seen are dropped). */
static inline uint32_t row_events(const float *row, long nx, long i0, float t, long *at)
{
    if (i0 + 32 <= nx || nx < 32) {
        *at = i0;
        return event_mask(row + i0, nx - i0 < 32 ? nx - i0 : 32, t);
    }
    const long s = nx - 32;
    *at = s;
    return event_mask(row + s, 32, t) & ~((1u << (i0 - s)) - 1u);
}

/* Pass 1 over the row (j, k), voxels vbase + i, i in [0, nx), for a
 * direction other than x: every voxel is on its own line, whose state is
 * pl[i], lastr[i]. Only events do anything. */
static void pass1_row(const sweep *w, const int d[3], ptrdiff_t stride, float t,
                      long j, long k, size_t vbase, uint8_t *pl, size_t *lastr)
{
    const float *row = w->data + vbase;
    const long nx = w->nx;
    const long fw_jk = lmin(steps_fwd(j, d[1], w->ny), steps_fwd(k, d[2], w->nz));
    const long bk_jk = lmin(steps_back(j, d[1], w->ny), steps_back(k, d[2], w->nz));
    for (long i0 = 0; i0 < nx; i0 += 32) {
        long at;
        uint32_t m = row_events(row, nx, i0, t, &at);
        while (m) {
            const long i = at + ctz32(m);
            m &= m - 1;
            const long bk = lmin(bk_jk, steps_back(i, d[0], nx));
            const size_t idx = vbase + (size_t)i;
            if (bk > 0 && w->data[(ptrdiff_t)idx - stride] < t)
                continue;           /* inside a run already walked */
            walk_run(w, stride, t, idx, bk, lmin(fw_jk, steps_fwd(i, d[0], nx)),
                     &pl[i], &lastr[i]);
        }
    }
}

/* Pass 2 at a marked voxel: the S mark counts at the voxel, the R mark
 * only after it; clears the marks. */
static inline void pass2_marked(const sweep *w, uint8_t *v, uint8_t *pl,
                                size_t lastr, size_t idx)
{
    const unsigned b = *v;
    unsigned s = *pl & P_STATE;
    if (b & MARK_S)
        s = (s ^ P_CS_ODD) | P_SEEN;
    const unsigned q = w->tab[s];
    *v = (uint8_t)(((b & ~MARKS) | (q & P_VIS)) + (q & P_ADD));
    if (b & MARK_R) {
        s ^= P_CR_ODD;
        if (idx == lastr)
            s |= P_PAST;
    }
    *pl = w->tab[s];
}

/* Line states pl[q] added to the 32 voxels v[q], q >= from; marked
 * voxels are left as they are. Branch-free. */
static const uint8_t FROM_RAMP[64] = {
    0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
    0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
    255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255,
    255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255, 255};
static inline void add32(uint8_t *restrict v, const uint8_t *restrict pl, long from)
{
    const uint8_t *keep = FROM_RAMP + 32 - from;   /* 255 where q >= from */
#ifdef __SSE2__
    const __m128i vis = _mm_set1_epi8((char)P_VIS), add = _mm_set1_epi8((char)P_ADD),
                  marks = _mm_set1_epi8((char)MARKS), zero = _mm_setzero_si128();
    for (int h = 0; h < 32; h += 16) {
        const __m128i b = _mm_loadu_si128((const __m128i *)(v + h));
        const __m128i p = _mm_and_si128(_mm_loadu_si128((const __m128i *)(pl + h)),
                                        _mm_loadu_si128((const __m128i *)(keep + h)));
        const __m128i nb = _mm_add_epi8(_mm_or_si128(b, _mm_and_si128(p, vis)),
                                        _mm_and_si128(p, add));
        const __m128i plain = _mm_cmpeq_epi8(_mm_and_si128(b, marks), zero);
        _mm_storeu_si128((__m128i *)(v + h),
                         _mm_or_si128(_mm_and_si128(plain, nb), _mm_andnot_si128(plain, b)));
    }
#else
    for (int q = 0; q < 32; q++) {
        unsigned b = v[q], p = pl[q] & keep[q];
        unsigned nb = ((b | (p & P_VIS)) + (p & P_ADD)) & 0xFFu;
        v[q] = (uint8_t)((b & MARKS) ? b : nb);
    }
#endif
}

/* One voxel of pass 2, the plain way (rows shorter than 32). */
static inline void pass2_one(const sweep *w, uint8_t *v, uint8_t *pl,
                             size_t lastr, size_t idx)
{
    if (*v & MARKS)
        pass2_marked(w, v, pl, lastr, idx);
    else
        *v = (uint8_t)((*v | (*pl & P_VIS)) + (*pl & P_ADD));
}

/* Pass 2 over a row for a direction other than x (each voxel on its own
 * line, state pl[i]): unmarked voxels take their line's addition
 * branch-free, 32 at a time; marked ones then update their lines. The
 * last 32 overlap the ones before, which add32 leaves alone. */
static void pass2_row(const sweep *w, size_t vbase, uint8_t *pl, const size_t *lastr)
{
    uint8_t *v = w->v + vbase;
    const long nx = w->nx;
    if (nx < 32) {
        for (long i = 0; i < nx; i++)
            pass2_one(w, &v[i], &pl[i], lastr[i], vbase + (size_t)i);
        return;
    }
    long i0 = 0;
    for (; i0 + 32 <= nx; i0 += 32) {
        const uint32_t m = mark_mask(v + i0, 32);
        add32(v + i0, pl + i0, 0);
        for (uint32_t mm = m; mm; mm &= mm - 1) {
            long i = i0 + ctz32(mm);
            pass2_marked(w, &v[i], &pl[i], lastr[i], vbase + (size_t)i);
        }
    }
    if (i0 < nx) {
        const long s = nx - 32;
        const uint32_t m = mark_mask(v + s, 32);   /* done ones have none */
        add32(v + s, pl + s, i0 - s);
        for (uint32_t mm = m; mm; mm &= mm - 1) {
            long i = s + ctz32(mm);
            pass2_marked(w, &v[i], &pl[i], lastr[i], vbase + (size_t)i);
        }
    }
}

/* The x direction: every row is a line, walked contiguously; its state is
 * one byte. Row r (both passes); rows are independent (sweep_x runs them
 * in parallel). */
static void x_row(const sweep *w, long r, float t)
{
    const long nx = w->nx;
    const size_t base = (size_t)r * (size_t)nx;
    const float *row = w->data + base;
    uint8_t pl = 0;
    size_t lastr = NO_MARK;
    for (long i0 = 0; i0 < nx; i0 += 32) {
        long at;
        uint32_t m = row_events(row, nx, i0, t, &at);
        while (m) {
            long i = at + ctz32(m);
            m &= m - 1;
            if (i > 0 && row[i - 1] < t)
                continue;
            walk_run(w, 1, t, base + (size_t)i, i, nx - 1 - i, &pl, &lastr);
        }
    }
    pl = w->tab[pl & P_E_ODD];
    uint8_t *v = w->v + base;
    if (nx < 32) {
        for (long i = 0; i < nx; i++)
            pass2_one(w, &v[i], &pl, lastr, base + (size_t)i);
        return;
    }
    for (long i0 = 0; i0 < nx; i0 += 32) {
        /* The last 32 overlap the ones before: from is where the new
         * voxels start in them. */
        const long s = i0 + 32 <= nx ? i0 : nx - 32, from = i0 - s;
        uint8_t *vv = v + s;
        const uint32_t m = mark_mask(vv, 32);
        if (!m && !from) {
            const unsigned vis = pl & P_VIS, add = pl & P_ADD;
            for (int q = 0; q < 32; q++)
                vv[q] = (uint8_t)((vv[q] | vis) + add);
            continue;
        }
        /* The line's state before each voxel: constant between marks;
         * a marked voxel is done on the spot and gets state 0. */
        uint8_t pp[32];
        long pos = from;
        memset(pp, 0, (size_t)from);
        for (uint32_t mm = m; mm; mm &= mm - 1) {
            const long q = ctz32(mm);
            memset(pp + pos, pl, (size_t)(q - pos));
            pass2_marked(w, &vv[q], &pl, lastr, base + (size_t)(s + q));
            pp[q] = 0;
            pos = q + 1;
        }
        memset(pp + pos, pl, (size_t)(32 - pos));
        add32(vv, pp, 0);
    }
}

static void sweep_x(const sweep *w)
{
    static const int d[3] = {1, 0, 0};
    const long rows = w->ny * w->nz;
    const float t = dir_event_distance(w, d);
    #pragma omp parallel for schedule(static)
    for (long r = 0; r < rows; r++)
        x_row(w, r, t);
}

/* Directions within a layer other than x (d[1] == 1, d[2] == 0): layers
 * are independent and run in parallel; in a layer, rows are streamed in
 * order with one state per line, named by i - dx j (shifted). */
static st_status sweep_in_layer(const sweep *w, const int d[3], ptrdiff_t stride)
{
    const long nx = w->nx, ny = w->ny, nz = w->nz;
    const float t = dir_event_distance(w, d);
    const long W = nx + (d[0] ? ny - 1 : 0);
    const long off = d[0] > 0 ? ny - 1 : 0;
    int oom = 0;
    #pragma omp parallel
    {
        uint8_t *pl = malloc((size_t)W);
        size_t *lastr = malloc((size_t)W * sizeof *lastr);
        if (!pl || !lastr) {
            #pragma omp atomic write
            oom = 1;
        }
        #pragma omp for schedule(dynamic, 1)
        for (long k = 0; k < nz; k++) {
            if (!pl || !lastr)
                continue;
            memset(pl, 0, (size_t)W);   /* lastr: see sweep_across */
            for (long j = 0; j < ny; j++) {
                size_t vbase = (size_t)nx * ((size_t)j + (size_t)ny * (size_t)k);
                long lbase = off - d[0] * j;
                pass1_row(w, d, stride, t, j, k, vbase, pl + lbase, lastr + lbase);
            }
            for (long l = 0; l < W; l++)
                pl[l] = w->tab[pl[l] & P_E_ODD];
            for (long j = 0; j < ny; j++) {
                size_t vbase = (size_t)nx * ((size_t)j + (size_t)ny * (size_t)k);
                long lbase = off - d[0] * j;
                pass2_row(w, vbase, pl + lbase, lastr + lbase);
            }
        }
        free(pl);
        free(lastr);
    }
    return oom ? ST_ENOMEM : ST_OK;
}

/* The nine directions that cross layers (d[2] == 1): one state per line.
 * A line is named by where it meets layer 0, (i - dx k, j - dy k), shifted
 * to be non-negative. Lines are independent, so a thread owns a block of
 * line rows (ly) and streams it through all layers, both passes, with no
 * barrier between layers; in layer k its rows are j = ly + dy k - offy,
 * LINE_ROWS consecutive rows of the grid, so a layer's share is one
 * contiguous stretch of memory. The block's line states are the thread's
 * own (LINE_ROWS x W), not a per-voxel array. */
#define LINE_ROWS 32
static st_status sweep_across(const sweep *w, const int d[3], ptrdiff_t stride)
{
    const long nx = w->nx, ny = w->ny, nz = w->nz;
    const long W = nx + (d[0] ? nz - 1 : 0), H = ny + (d[1] ? nz - 1 : 0);
    const long offx = d[0] > 0 ? nz - 1 : 0, offy = d[1] > 0 ? nz - 1 : 0;
    const float t = dir_event_distance(w, d);
    const size_t nl = (size_t)W * LINE_ROWS;
    int oom = 0;
    #pragma omp parallel
    {
        uint8_t *pl = malloc(nl);
        size_t *lastr = malloc(nl * sizeof *lastr);
        if (!pl || !lastr) {
            #pragma omp atomic write
            oom = 1;
        }
        #pragma omp for schedule(dynamic, 1)
        for (long ly0 = 0; ly0 < H; ly0 += LINE_ROWS) {
            if (!pl || !lastr)
                continue;
            const long ly1 = ly0 + LINE_ROWS < H ? ly0 + LINE_ROWS : H;
            /* lastr[l] needs no start value: pass 2 reads it only at an R
             * mark, and a line with a mark had it written in pass 1. */
            memset(pl, 0, nl);
            for (int pass = 1; pass <= 2; pass++) {
                if (pass == 2)
                    for (size_t l = 0; l < nl; l++)
                        pl[l] = w->tab[pl[l] & P_E_ODD];
                for (long k = 0; k < nz; k++)
                    for (long ly = ly0; ly < ly1; ly++) {
                        const long j = ly + d[1] * k - offy;
                        if (j < 0 || j >= ny)
                            continue;
                        const size_t lbase = (size_t)(W * (ly - ly0) - d[0] * k + offx);
                        const size_t vbase = (size_t)nx * ((size_t)j + (size_t)ny * (size_t)k);
                        if (pass == 1)
                            pass1_row(w, d, stride, t, j, k, vbase, pl + lbase, lastr + lbase);
                        else
                            pass2_row(w, vbase, pl + lbase, lastr + lbase);
                    }
            }
        }
        free(pl);
        free(lastr);
    }
    return oom ? ST_ENOMEM : ST_OK;
}

static void sweep_init(sweep *w, const st_grid *g, const st_sign_params *p,
                       const float *data, uint8_t *v, float t_axis)
{
    w->data = data;
    w->v = v;
    w->nx = (long)g->nx;
    w->ny = (long)g->ny;
    w->nz = (long)g->nz;
    w->toggle = p->toggle;
    w->t_axis = t_axis;
    w->k1 = p->k >= 1.0;
    w->split = p->split_runs && p->toggle == ST_TOGGLE_CROSSING;
    w->count = NULL;
    sweep_table(w, p);
}

/* The decision: -|d| (st_grid_signed_value) where the voxel is inside (majority, or with the
 * union rule hidden along every ray), |d| elsewhere; n voxels from out and
 * their bytes v. Branch-free, 16 voxels at a time. */
#define SIGN_BLOCK ((size_t)1 << 16)
static void write_signs(float *out, const uint8_t *v, size_t n, int nested)
{
    size_t i = 0;
#ifdef __SSE2__
    const __m128i count = _mm_set1_epi8((char)V_COUNT), vis = _mm_set1_epi8((char)V_VISIBLE),
                  half = _mm_set1_epi8(13), zero = _mm_setzero_si128(),
                  sign = _mm_set1_epi32((int)0x80000000u), mag = _mm_set1_epi32(0x7FFFFFFF),
                  fmin = _mm_set1_epi32(0x00800000), /* FLT_MIN's bits */
                  use_vis = nested ? _mm_set1_epi8(-1) : zero;
    for (; i + 16 <= n; i += 16) {
        const __m128i b = _mm_loadu_si128((const __m128i *)(v + i));
        /* vote_inside: U > 13 (U <= 26, so a signed byte compare) */
        __m128i in = _mm_cmpgt_epi8(_mm_and_si128(b, count), half);
        in = _mm_or_si128(in, _mm_and_si128(use_vis,
                                            _mm_cmpeq_epi8(_mm_and_si128(b, vis), zero)));
        const __m128i lo = _mm_unpacklo_epi8(in, in), hi = _mm_unpackhi_epi8(in, in);
        const __m128i m[4] = {_mm_unpacklo_epi16(lo, lo), _mm_unpackhi_epi16(lo, lo),
                              _mm_unpacklo_epi16(hi, hi), _mm_unpackhi_epi16(hi, hi)};
        for (int q = 0; q < 4; q++) {
            __m128i *o = (__m128i *)(out + i + 4 * q);
            /* st_grid_signed_value: |d|, negative inside, -FLT_MIN
             * for an inside voxel at distance 0 */
            const __m128i a = _mm_and_si128(_mm_loadu_si128(o), mag);
            const __m128i tiny = _mm_and_si128(_mm_and_si128(m[q], _mm_cmpeq_epi32(a, zero)), fmin);
            _mm_storeu_si128(o, _mm_or_si128(_mm_or_si128(a, tiny), _mm_and_si128(m[q], sign)));
        }
    }
#endif
    for (; i < n; i++) {
        const unsigned b = v[i];
        const int inside = vote_inside(b & V_COUNT) || (nested && !(b & V_VISIBLE));
        out[i] = st_grid_signed_value(out[i], inside);
    }
}

/* The undecided voxels by a minimum cut (mincut.h), the votes as its
 * evidence: a majority inside is evidence for inside (U - 13, 1..13); a
 * minority is evidence for outside (U - 13) only where some ray sees the
 * voxel from outside, since a voxel hidden along every ray (inside
 * interpenetrating shells, or in a tunnel) is where parity is not to be
 * trusted: it has none, and the cut joins it to the side that encloses it
 * (the union rule's intent, decided by area rather than by straight
 * rays; without nested_union, parity is trusted there too). Each voxel's byte becomes its evidence, then its label; the
 * signs are written from the labels. */
static st_status cut_undecided(st_grid *g, uint8_t *v, int nested, const int8_t *extra,
                               st_error *err)
{
    const size_t n = st_grid_count(g);
    int8_t *e = (int8_t *)v;
    #pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        const int u = v[i] & V_COUNT, vis = (v[i] & V_VISIBLE) != 0;
        int ev = u > 13 || vis || !nested ? u - 13 : 0;
        if (extra) {
            ev += extra[i];
            ev = ev < -127 ? -127 : ev > 127 ? 127 : ev;
        }
        e[i] = (int8_t)ev;
    }
    const st_mincut_params cp = st_mincut_params_default();
    st_status st = st_mincut_label(g, e, &cp, NULL, err);
    if (st)
        return st;
    float *out = g->data;
    #pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++)
        out[i] = st_grid_signed_value(out[i], e[i]);
    return ST_OK;
}

unsigned st_sign_line(const float *d, size_t n, float t,
                      const st_sign_params *p, unsigned char *votes,
                      unsigned char *valid)
{
    /* A n x 1 x 1 grid of the samples, swept like an x row. */
    float *a = calloc(n ? n : 1, sizeof *a);
    uint8_t *v = calloc(n ? n : 1, 1);
    if (!a || !v) {
        free(a);
        free(v);
        return 0;
    }
    unsigned events = 0;
    for (size_t i = 0; i < n; i++)
        a[i] = fabsf(d[i]);
    st_grid g;
    memset(&g, 0, sizeof g);
    g.nx = n;
    g.ny = g.nz = 1;
    g.data = a;
    sweep w;
    sweep_init(&w, &g, p, a, v, t);
    w.count = &events;
    if (n)
        x_row(&w, 0, t);            /* t is the line's own */
    const int counted = !(p->ignore_odd && (events & 1u));
    for (size_t i = 0; i < n && counted; i++) {
        unsigned u = v[i] & V_COUNT;
        votes[i] = (unsigned char)(votes[i] + (p->rays == 26 ? u : u / 2));
        if (valid)
            valid[i] = (unsigned char)(valid[i] + (p->rays == 26 ? 2 : 1));
    }
    free(a);
    free(v);
    return events;
}

st_status st_sign_check_params(const st_sign_params *p, st_error *err)
{
    if (!(p->k > 0.0 && p->k <= 1.0))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "k must be in (0, 1], not %g", p->k);
    if (p->rays != 13 && p->rays != 26)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "rays must be 13 or 26, not %d", p->rays);
    return ST_OK;
}

st_status st_sign_check_field(const st_grid *g, const st_sign_params *p, st_error *err)
{
    if (g->kind == ST_GRID_SIGNED)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "the field is already signed (give soupsign a "
                            "distance field from soupdist)");
    if (g->kind != ST_GRID_DISTANCE && g->kind != ST_GRID_UNKNOWN)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "not a distance field");
    st_status ps = st_sign_check_params(p, err);
    if (ps)
        return ps;
    const size_t n = st_grid_count(g);
    /* One branch-free pass (vectorised, 32-bit counts per block): not
     * finite, negative, and different from the first value (a constant
     * field has no surface). */
    const float *data = g->data;
    const float first = n ? data[0] : INFINITY;
    size_t negative = 0, nonfinite = 0, differ = 0;
    enum { BLOCK = 1 << 16 };
    #pragma omp parallel for reduction(+ : negative, nonfinite, differ) schedule(static)
    for (size_t b0 = 0; b0 < n; b0 += BLOCK) {
        const size_t b1 = n - b0 < BLOCK ? n : b0 + BLOCK;
        uint32_t neg = 0, nonf = 0, diff = 0;
        #pragma omp simd reduction(+ : neg, nonf, diff)
        for (size_t i = b0; i < b1; i++) {
            const float x = data[i];
            nonf += !(fabsf(x) <= FLT_MAX);
            neg += x < 0.0f;
            diff += x != first;
        }
        negative += neg;
        nonfinite += nonf;
        differ += diff;
    }
    if (nonfinite)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "the field has %zu values that are not finite",
                            nonfinite);
    if (negative)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "not an unsigned distance field: %zu values are "
                            "negative", negative);
    if (!differ)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "the field is constant (%g): no surface in it",
                            (double)first);
    return ST_OK;
}

/* The checks and the 13 sweeps: v (n bytes, zeroed) gets every voxel's
 * votes (see above). */
static st_status vote_all(const st_grid *g, const st_sign_params *p, uint8_t *v,
                          const st_progress *progress, st_error *err)
{
    st_status cs = st_sign_check_field(g, p, err);
    if (cs)
        return cs;
    const double t = st_sign_event_distance(p, g);
    sweep w;
    sweep_init(&w, (st_grid *)g, p, g->data, v, (float)t);
    st_status st = ST_OK;
    for (int d = 0; d < 13 && !st; d++) {
        if (st_progress_cancelled(progress))
            return st_error_set(err, ST_ECANCELLED, NULL, 0, "cancelled");
        /* Every direction is walked forward in memory (see DIRS). */
        const ptrdiff_t stride = (ptrdiff_t)DIRS[d][0] +
            (ptrdiff_t)g->nx * ((ptrdiff_t)DIRS[d][1] + (ptrdiff_t)g->ny * (ptrdiff_t)DIRS[d][2]);
        if (d == 0)
            sweep_x(&w);
        else if (d < IN_LAYER)
            st = sweep_in_layer(&w, DIRS[d], stride);
        else
            st = sweep_across(&w, DIRS[d], stride);
        st_progress_report(progress, "signs", (d + 1) / 13.0);
    }
    if (st)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    return ST_OK;
}

st_status st_sign_votes(const st_grid *g, const st_sign_params *p, uint8_t *votes,
                        st_error *err)
{
    return st_sign_votes_progress(g, p, votes, NULL, err);
}

st_status st_sign_votes_progress(const st_grid *g, const st_sign_params *p, uint8_t *votes,
                                 const st_progress *progress, st_error *err)
{
    const size_t n = st_grid_count(g);
    memset(votes, 0, n);
    st_status st = vote_all(g, p, votes, progress, err);
    if (st)
        return st;
    #pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n; i++) {
        const unsigned b = votes[i];
        votes[i] = (uint8_t)((b & (V_COUNT | V_VISIBLE)) |
                             (vote_inside(b & V_COUNT) || (p->nested_union && !(b & V_VISIBLE))
                                  ? ST_SIGN_VOTES_INSIDE : 0u));
    }
    return ST_OK;
}

st_status st_sign_field(st_grid *g, const st_sign_params *p,
                        const st_progress *progress, st_error *err)
{
    return st_sign_field_evidence(g, p, NULL, NULL, progress, err);
}

st_status st_sign_field_evidence(st_grid *g, const st_sign_params *p, const int8_t *extra,
                                 uint8_t *votes, const st_progress *progress, st_error *err)
{
    const size_t n = st_grid_count(g);
    uint8_t *v = votes;
    if (v) {
        /* st_sign_votes' bytes: the count and the seen bit are ours */
        #pragma omp parallel for schedule(static)
        for (size_t i = 0; i < n; i++)
            v[i] &= (uint8_t)(V_COUNT | V_VISIBLE);
    } else {
        v = st_calloc_big(n ? n : 1);
        if (!v)
            return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory for the votes");
        st_status st = vote_all(g, p, v, progress, err);
        if (st) {
            free(v);
            return st;
        }
    }
    const double t = st_sign_event_distance(p, g);
    /* With the cut, the votes are its evidence (cut_undecided). Without:
     * majority; ties (and voxels no counted ray reached) are outside; with
     * nested_union, a voxel no ray reaches from outside without meeting
     * the surface is inside whatever the parity. */
    float *out = g->data;
    if (p->cut) {
        st_status cs = cut_undecided(g, v, p->nested_union, extra, err);
        if (cs) {
            if (!votes)
                free(v);
            return cs;
        }
    } else {
        #pragma omp parallel for schedule(static)
        for (size_t b0 = 0; b0 < n; b0 += SIGN_BLOCK)
            write_signs(out + b0, v + b0, n - b0 < SIGN_BLOCK ? n - b0 : SIGN_BLOCK,
                        p->nested_union);
    }
    if (!votes)
        free(v);
    g->kind = ST_GRID_SIGNED;
    char buf[160];
    snprintf(buf, sizeof buf,
             "k=%g c=%s rays=%d toggle=%s odd=%s nested=%s runs=%s "
             "undecided=%s event_distance=%.9g",
             p->k, p->band_voxels > 0 ? "band" : "1/max|d|", p->rays,
             p->toggle == ST_TOGGLE_CROSSING ? "crossing"
                 : p->toggle == ST_TOGGLE_NEAREST ? "nearest" : "first",
             p->ignore_odd ? "ignored" : "kept",
             p->nested_union ? "union" : "parity",
             p->split_runs && p->toggle == ST_TOGGLE_CROSSING ? "split" : "whole",
             p->cut ? "cut" : "vote", t);
    if (st_meta_set(&g->meta, "sign_rule", buf))
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    return ST_OK;
}

/* --- near-surface refinement (sign.h) ---------------------------------- */

st_sign_refine_params st_sign_refine_params_default(void)
{
    /* band 1.5 voxels: the answers are only as good as the confident
     * neighbours' votes, and on thin parts some votes between 1 and 1.5
     * voxels from the surface are wrong too. Radius 2: a voxel inside a
     * feature thinner than a voxel still finds neighbours 1.5 voxels from
     * it. Up to 6 answers, unanimous: a disagreement (a hole, an overlap
     * of interpenetrating shells, whose inner faces do not separate
     * inside from outside) leaves the vote. Measured: doc/design/sign.md. */
    st_sign_refine_params p = {1.5, 2, 6};
    return p;
}

typedef struct refine_tri {
    double lo[3], hi[3];
    uint32_t id;
} refine_tri;

typedef struct refine_buf {
    refine_tri *t;
    size_t n, cap;
    int oom;
    const st_soup *s;
    uint32_t base;      /* the queried BVH's first triangle in s */
} refine_buf;

static int refine_collect(void *ctx, uint32_t tri)
{
    refine_buf *b = ctx;
    if (b->n == b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 64;
        refine_tri *t = st_realloc_array(b->t, cap, sizeof *t);
        if (!t) {
            b->oom = 1;
            return 1;
        }
        b->t = t;
        b->cap = cap;
    }
    refine_tri *r = &b->t[b->n++];
    tri += b->base;
    r->id = tri;
    for (int a = 0; a < 3; a++) {
        r->lo[a] = INFINITY;
        r->hi[a] = -INFINITY;
    }
    for (int v = 0; v < 3; v++) {
        const double *x = b->s->xyz + 3 * (size_t)b->s->tris[3 * (size_t)tri + v];
        for (int a = 0; a < 3; a++) {
            if (x[a] < r->lo[a])
                r->lo[a] = x[a];
            if (x[a] > r->hi[a])
                r->hi[a] = x[a];
        }
    }
    return 0;
}

static int sgn(double x) { return (x > 0) - (x < 0); }

/* How the closed segment [p, q] meets triangle (a b c): 0 not at all,
 * 1 a proper crossing (through the triangle's open interior, the ends off
 * its plane), -1 any other contact (an end on the triangle, through an
 * edge or a vertex, in its plane): degenerate, the caller takes another
 * segment. Exact (orient3d signs; st_segment_tri_intersect for contacts
 * the signs alone do not settle). */
static int segment_crossing(const double p[3], const double q[3],
                            const double a[3], const double b[3],
                            const double c[3])
{
    int sp = sgn(st_orient3d(a, b, c, p)), sq = sgn(st_orient3d(a, b, c, q));
    if (sp != 0 && sp == sq)
        return 0;
    if (sp == 0 || sq == 0)   /* an end in the plane, or the segment in it */
        return st_segment_tri_intersect(p, q, a, b, c) ? -1 : 0;
    int e1 = sgn(st_orient3d(p, q, a, b)), e2 = sgn(st_orient3d(p, q, b, c)),
        e3 = sgn(st_orient3d(p, q, c, a));
    if ((e1 > 0 || e2 > 0 || e3 > 0) && (e1 < 0 || e2 < 0 || e3 < 0))
        return 0;             /* the line passes beside the triangle */
    if (e1 == 0 || e2 == 0 || e3 == 0)
        return -1;            /* through an edge or a vertex */
    return 1;
}

/* Do triangles i and j have the same three vertex positions? */
static int same_tri(const st_soup *s, uint32_t i, uint32_t j)
{
    const uint32_t *ti = s->tris + 3 * (size_t)i, *tj = s->tris + 3 * (size_t)j;
    int used[3] = {0, 0, 0};
    for (int u = 0; u < 3; u++) {
        const double *x = s->xyz + 3 * (size_t)ti[u];
        int found = 0;
        for (int v = 0; v < 3 && !found; v++) {
            const double *y = s->xyz + 3 * (size_t)tj[v];
            if (!used[v] && x[0] == y[0] && x[1] == y[1] && x[2] == y[2])
                used[v] = found = 1;
        }
        if (!found)
            return 0;
    }
    return 1;
}

/* Crossings of segment [p, q] with the candidate triangles: the parity of
 * the distinct triangles crossed, or -1 when a contact is degenerate. */
#define MAX_CROSSED 64
static int segment_parity(const st_soup *s, const refine_buf *b,
                          const uint32_t *sel, size_t nsel,
                          const double p[3], const double q[3])
{
    double lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = p[a] < q[a] ? p[a] : q[a];
        hi[a] = p[a] < q[a] ? q[a] : p[a];
    }
    uint32_t crossed[MAX_CROSSED];
    size_t nc = 0;
    for (size_t t = 0; t < nsel; t++) {
        const refine_tri *r = &b->t[sel[t]];
        if (r->hi[0] < lo[0] || r->lo[0] > hi[0] || r->hi[1] < lo[1] ||
            r->lo[1] > hi[1] || r->hi[2] < lo[2] || r->lo[2] > hi[2])
            continue;
        const uint32_t *v = s->tris + 3 * (size_t)r->id;
        int x = segment_crossing(p, q, s->xyz + 3 * (size_t)v[0],
                                 s->xyz + 3 * (size_t)v[1], s->xyz + 3 * (size_t)v[2]);
        if (x < 0)
            return -1;
        if (x == 0)
            continue;
        int dup = 0;
        for (size_t e = 0; e < nc && !dup; e++)
            dup = same_tri(s, crossed[e], r->id);
        if (dup)
            continue;
        if (nc == MAX_CROSSED)
            return -1;        /* a pathological pile of faces: not used */
        crossed[nc++] = r->id;
    }
    return (int)(nc & 1u);
}

typedef struct refine_offset {
    int d[3];
    int len2;
    int cheb;   /* max |d[a]|: the reach its segment needs */
} refine_offset;

static int offset_cmp(const void *x, const void *y)
{
    const refine_offset *a = x, *b = y;
    if (a->cheb != b->cheb)
        return a->cheb < b->cheb ? -1 : 1;
    if (a->len2 != b->len2)
        return a->len2 < b->len2 ? -1 : 1;
    for (int k = 2; k >= 0; k--)
        if (a->d[k] != b->d[k])
            return a->d[k] < b->d[k] ? -1 : 1;
    return 0;
}

st_status st_sign_refine(st_grid *g, const st_soup *soup,
                         const st_sign_refine_params *p, size_t *changed,
                         st_error *err)
{
    if (changed)
        *changed = 0;
    if (!soup || soup->ntris == 0)
        return st_error_set(err, ST_EINPUT, NULL, 0, "no triangles to refine with");
    st_bvh *bvh = NULL;
    st_status st = st_bvh_build(&bvh, soup, err);
    if (st)
        return st;
    st = st_sign_refine_bvh(g, bvh, p, changed, err);
    st_bvh_free(bvh);
    return st;
}

/* The neighbour offsets within radius voxels per axis, nearest first
 * (offset_cmp); returns how many (offs holds 7^3). */
static int refine_offsets(refine_offset *offs, int radius)
{
    int noffs = 0;
    for (int z = -radius; z <= radius; z++)
        for (int y = -radius; y <= radius; y++)
            for (int x = -radius; x <= radius; x++)
                if (x || y || z) {
                    int ax = abs(x), ay = abs(y), az = abs(z);
                    int cheb = ax > ay ? (ax > az ? ax : az) : (ay > az ? ay : az);
                    refine_offset o = {{x, y, z}, x * x + y * y + z * z, cheb};
                    offs[noffs++] = o;
                }
    qsort(offs, (size_t)noffs, sizeof *offs, offset_cmp);
    return noffs;
}

/* The refinement of one field, read by every thread. Tiles of TILE^3
 * voxels share one BVH query (the query and the candidates' boxes cost
 * more than the exact tests); each voxel then keeps the candidates whose
 * boxes meet its own reach. */
enum { TILE = 4 };
typedef struct refine_ctx {
    const st_grid *g;
    const st_soup *soup;
    const st_bvh *const *bvhs;  /* over soup's triangles, in order */
    size_t nbvh;
    const st_sign_refine_params *p;
    refine_offset offs[7 * 7 * 7];
    int noffs;
    float band;
    double reach;
    long nx, ny, nz, tx, ty;
} refine_ctx;

/* One thread's: the candidates of its tile (b), those near the voxel
 * (sel, indices into b) and the sign flips it found. */
typedef struct refine_worker {
    refine_buf b;
    uint32_t *sel;      /* in the mask's block */
    size_t nsel;
    int seloom;
    size_t *flip, nflip, flipcap;
    /* the tile's candidates near each of its voxel coordinates, per axis
     * and reach (1..radius voxels): a bit per candidate, mask[((reach -
     * 1) * 3 + axis) * TILE + coordinate - the tile's first][word]; a
     * reach's masks made when a voxel of the tile first needs it */
    uint64_t *mask;
    size_t words, maskcap;
    int made[3];
    long first[3];
} refine_worker;

/* The masks of reach `have` voxels for w's tile (refine_worker). */
static void near_masks(const refine_ctx *c, refine_worker *w, int have)
{
    const st_grid *g = c->g;
    const double rr = have * g->voxel;
    for (int a = 0; a < 3; a++)
        for (int d = 0; d < TILE; d++) {
            uint64_t *m = w->mask + (((size_t)(have - 1) * 3 + (size_t)a) * TILE +
                                     (size_t)d) * w->words;
            /* the voxel centre's coordinate, as st_grid_center has it */
            const double x = g->origin[a] + g->voxel * (double)(w->first[a] + d);
            for (size_t q0 = 0; q0 < w->b.n; q0 += 64) {
                const size_t q1 = w->b.n - q0 < 64 ? w->b.n : q0 + 64;
                uint64_t bits = 0;
                for (size_t q = q0; q < q1; q++) {
                    const refine_tri *r = &w->b.t[q];
                    const int in = !(r->hi[a] < x - rr) & !(r->lo[a] > x + rr);
                    bits |= (uint64_t)in << (q - q0);
                }
                m[q0 / 64] = bits;
            }
        }
    w->made[have - 1] = 1;
}

/* w->sel: the tile's candidates whose boxes meet the box of `have`
 * voxels around voxel (i, j, k), in their order. */
static void select_near(const refine_ctx *c, refine_worker *w, long i, long j, long k, int have)
{
    if (!w->made[have - 1])
        near_masks(c, w, have);
    const size_t W = w->words, base = (size_t)(have - 1) * 3 * TILE;
    const uint64_t *mx = w->mask + (base + (size_t)(i - w->first[0])) * W;
    const uint64_t *my = w->mask + (base + TILE + (size_t)(j - w->first[1])) * W;
    const uint64_t *mz = w->mask + (base + 2 * TILE + (size_t)(k - w->first[2])) * W;
    w->nsel = 0;
    for (size_t q = 0; q < W; q++)
        for (uint64_t m = mx[q] & my[q] & mz[q]; m; m &= m - 1)
            w->sel[w->nsel++] = (uint32_t)(64 * q + (size_t)st_lowest_bit(m));
}

/* Whether voxel (i, j, k) at pv, of value dv, is inside: its neighbours'
 * answers (the parity of the soup's crossings on the segment to each
 * confident neighbour, from its sign), unanimous against the vote, else
 * the vote. */
static int refine_voxel(const refine_ctx *c, refine_worker *w, long i, long j, long k,
                        const double pv[3], float dv)
{
    const st_grid *g = c->g;
    const refine_offset *offs = c->offs;
    /* The candidates within the reach of the neighbours taken so far:
     * offsets come nearest first, so grow the reach only when needed. */
    int have = 0;
    int nin = 0, nout = 0;
    for (int o = 0; o < c->noffs && nin + nout < c->p->answers; o++) {
        long ui = i + offs[o].d[0], uj = j + offs[o].d[1], uk = k + offs[o].d[2];
        if (ui < 0 || ui >= c->nx || uj < 0 || uj >= c->ny || uk < 0 || uk >= c->nz)
            continue;
        float du = g->data[st_grid_index(g, (size_t)ui, (size_t)uj, (size_t)uk)];
        if (fabsf(du) < c->band)
            continue;
        if (offs[o].cheb > have) {
            have = offs[o].cheb;
            select_near(c, w, i, j, k, have);
        }
        double pu[3];
        st_grid_center(g, (size_t)ui, (size_t)uj, (size_t)uk, pu);
        int par = segment_parity(c->soup, &w->b, w->sel, w->nsel, pv, pu);
        if (par < 0)
            continue;
        if ((du < 0) ^ par)
            nin++;
        else
            nout++;
        /* One answer that agrees with the vote settles it (only a
         * unanimous answer against the vote changes a sign), so stop: the
         * same result, one segment for most voxels. */
        if ((dv < 0) ? nin : nout)
            break;
    }
    int inside = dv < 0;
    if (nin && !nout)
        inside = 1;
    else if (nout && !nin)
        inside = 0;
    return inside;
}

/* Tile t: the voxels in the band whose sign the answers change, listed
 * in w->flip (the grid is not written: the neighbours read may lie in
 * another thread's tile). Out of memory: w->b.oom or w->seloom. */
static void refine_tile(const refine_ctx *c, refine_worker *w, long t)
{
    const st_grid *g = c->g;
    const long i0 = (t % c->tx) * TILE, j0 = ((t / c->tx) % c->ty) * TILE,
               k0 = (t / (c->tx * c->ty)) * TILE;
    const long i1 = i0 + TILE < c->nx ? i0 + TILE : c->nx,
               j1 = j0 + TILE < c->ny ? j0 + TILE : c->ny,
               k1 = k0 + TILE < c->nz ? k0 + TILE : c->nz;
    int any = 0;
    for (long k = k0; k < k1 && !any; k++)
        for (long j = j0; j < j1 && !any; j++)
            for (long i = i0; i < i1 && !any; i++)
                any = fabsf(g->data[st_grid_index(g, (size_t)i, (size_t)j, (size_t)k)]) < c->band;
    if (!any)
        return;
    double lo[3], hi[3], plo[3], phi[3];
    st_grid_center(g, (size_t)i0, (size_t)j0, (size_t)k0, plo);
    st_grid_center(g, (size_t)(i1 - 1), (size_t)(j1 - 1), (size_t)(k1 - 1), phi);
    for (int a = 0; a < 3; a++) {
        lo[a] = plo[a] - c->reach;
        hi[a] = phi[a] + c->reach;
    }
    w->b.n = 0;
    w->b.base = 0;
    for (size_t q = 0; q < c->nbvh && !w->b.oom; q++) {
        st_bvh_query_box(c->bvhs[q], lo, hi, refine_collect, &w->b);
        w->b.base += (uint32_t)c->bvhs[q]->soup->ntris;
    }
    if (w->b.oom)
        return;
    /* the masks, then sel (b.n indices, two a word) in one block */
    w->words = (w->b.n + 63) / 64;
    const size_t nmask = (size_t)c->p->radius * 3 * TILE * w->words;
    const size_t need = nmask + (w->b.n + 1) / 2;
    if (w->maskcap < need) {
        uint64_t *nm = st_realloc_array(w->mask, need, sizeof *nm);
        if (!nm) {
            w->seloom = 1;
            return;
        }
        w->mask = nm;
        w->maskcap = need;
    }
    w->sel = (uint32_t *)(w->mask + nmask);
    w->made[0] = w->made[1] = w->made[2] = 0;
    w->first[0] = i0, w->first[1] = j0, w->first[2] = k0;
    for (long k = k0; k < k1; k++)
        for (long j = j0; j < j1; j++)
            for (long i = i0; i < i1; i++) {
                size_t idx = st_grid_index(g, (size_t)i, (size_t)j, (size_t)k);
                float dv = g->data[idx];
                if (!(fabsf(dv) < c->band))
                    continue;
                double pv[3];
                st_grid_center(g, (size_t)i, (size_t)j, (size_t)k, pv);
                if (refine_voxel(c, w, i, j, k, pv, dv) == (dv < 0))
                    continue;
                if (w->nflip == w->flipcap) {
                    size_t cap = w->flipcap ? 2 * w->flipcap : 256;
                    size_t *nf = st_realloc_array(w->flip, cap, sizeof *nf);
                    if (!nf) {
                        w->seloom = 1;
                        continue;
                    }
                    w->flip = nf;
                    w->flipcap = cap;
                }
                w->flip[w->nflip++] = idx;
            }
}

st_status st_sign_refine_bvh(st_grid *g, const st_bvh *bvh,
                             const st_sign_refine_params *p, size_t *changed,
                             st_error *err)
{
    return st_sign_refine_parts(g, bvh ? bvh->soup : NULL, &bvh, bvh ? 1 : 0, p, changed, err);
}

st_status st_sign_refine_parts(st_grid *g, const st_soup *soup, const st_bvh *const *bvhs,
                               size_t nbvh, const st_sign_refine_params *p, size_t *changed,
                               st_error *err)
{
    if (changed)
        *changed = 0;
    size_t parts = 0;
    for (size_t q = 0; q < nbvh; q++)
        parts += bvhs[q]->soup->ntris;
    if (soup && parts != soup->ntris)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "the BVHs hold %zu triangles, the soup %zu", parts, soup->ntris);
    if (g->kind != ST_GRID_SIGNED)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "refinement needs a signed field");
    if (!(p->band_voxels > 0 && p->band_voxels <= 8) || p->radius < 1 ||
        p->radius > 3 || p->answers < 1)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "bad refinement parameters (band %g, radius %d, "
                            "answers %d)", p->band_voxels, p->radius, p->answers);
    if (!soup || soup->ntris == 0)
        return st_error_set(err, ST_EINPUT, NULL, 0, "no triangles to refine with");
    refine_ctx c;
    c.g = g;
    c.soup = soup;
    c.bvhs = bvhs;
    c.nbvh = nbvh;
    c.p = p;
    c.noffs = refine_offsets(c.offs, p->radius);
    c.band = (float)(p->band_voxels * g->voxel);
    c.nx = (long)g->nx, c.ny = (long)g->ny, c.nz = (long)g->nz;
    c.reach = p->radius * g->voxel;
    c.tx = (c.nx + TILE - 1) / TILE, c.ty = (c.ny + TILE - 1) / TILE;
    const long ntiles = c.tx * c.ty * ((c.nz + TILE - 1) / TILE);
    size_t nchanged = 0;
    int oom = 0;
    /* No voxel is rewritten while the tiles are decided: each thread
     * lists the sign flips it found and applies them after the loop's
     * barrier. (A flipped voxel is in the band, which no neighbour test
     * uses, so the answers are the same; this removes the data race.) */
    #pragma omp parallel reduction(+ : nchanged)
    {
        refine_worker w = {{NULL, 0, 0, 0, soup, 0}, NULL, 0, 0, NULL, 0, 0,
                           NULL, 0, 0, {0, 0, 0}, {0, 0, 0}};
        #pragma omp for schedule(dynamic, 4)
        for (long t = 0; t < ntiles; t++)
            if (!w.b.oom && !w.seloom)
                refine_tile(&c, &w, t);
        /* (the implicit barrier of the loop above: every read is done) */
        for (size_t f = 0; f < w.nflip; f++) {
            float dv = g->data[w.flip[f]];
            g->data[w.flip[f]] = st_grid_signed_value(dv, !(dv < 0));
        }
        nchanged += w.nflip;
        free(w.flip);
        if (w.b.oom || w.seloom) {
            #pragma omp atomic write
            oom = 1;
        }
        free(w.b.t);
        free(w.mask);
    }
    if (oom)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory in the refinement");
    if (changed)
        *changed = nchanged;
    char buf[128];
    snprintf(buf, sizeof buf, "band=%g radius=%d answers=%d unanimous exact",
             p->band_voxels, p->radius, p->answers);
    if (st_meta_set(&g->meta, "sign_refine", buf))
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    return ST_OK;
}
