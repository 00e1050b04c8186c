/*
 * tetmesh.c - tetrahedral meshes: building, named arrays, compaction,
 * face adjacency and the oriented boundary (see tetmesh.h).
 *
 * Adjacency. Every tet contributes its four faces, each keyed by its three
 * point indices sorted. The faces are bucketed by their smallest index (a
 * counting sort, linear) and each bucket is sorted by the two other
 * indices and then by (tet, corner), so equal faces end up next to each
 * other in an order that depends only on the mesh: no hashing, no thread
 * count, no allocator addresses. A run of one face is on the boundary, a
 * run of two is an interior face, a longer run is non-manifold.
 *
 * Orientation. For a positively oriented tet (a, b, c, d) (signed volume
 * det[b-a, c-a, d-a] > 0) the faces opposite its corners, written so that
 * their normals (q-p)x(r-p) point away from the tet, are
 *     opposite a: (b, c, d)   opposite b: (a, d, c)
 *     opposite c: (a, b, d)   opposite d: (a, c, b)
 * (for the face opposite d: (d-a).((b-a)x(c-a)) = det[b-a, c-a, d-a] > 0,
 * so (a, b, c) faces d and (a, c, b) faces away; the others follow by the
 * same column swaps). This is combinatorial: no predicate is evaluated.
 */
#include "souptet/tetmesh.h"
#include "../base/fpenv.h"
#include "souptet/mem.h"
#include "souptet/pred.h"
#include "souptet/soup.h"
#include "souptet/tetqual.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The face of a tet opposite each corner, outward for positive tets. */
static const int k_face[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

/* ---- building ------------------------------------------------------------ */

st_tetmesh *st_tetmesh_new(void)
{
    return calloc(1, sizeof(st_tetmesh));
}

static void free_array(st_tet_array *a)
{
    free(a->name);
    free(a->values);
    a->name = NULL;
    a->values = NULL;
}

void st_tetmesh_clear_arrays(st_tetmesh *m)
{
    if (!m)
        return;
    for (size_t i = 0; i < m->narrays; i++)
        free_array(&m->arrays[i]);
    free(m->arrays);
    m->arrays = NULL;
    m->narrays = 0;
}

void st_tetmesh_free(st_tetmesh *m)
{
    if (!m)
        return;
    st_tetmesh_clear_arrays(m);
    free(m->xyz);
    free(m->tets);
    st_meta_clear(&m->meta);
    free(m);
}

st_status st_tetmesh_reserve(st_tetmesh *m, size_t npoints, size_t ntets,
                             st_error *err)
{
    if (npoints > m->cap_points) {
        double *p = st_realloc_array(m->xyz, npoints, 3 * sizeof(double));
        if (!p)
            return st_error_set(err, ST_ENOMEM, NULL, 0,
                                "out of memory for %zu mesh points", npoints);
        m->xyz = p;
        m->cap_points = npoints;
    }
    if (ntets > m->cap_tets) {
        uint32_t *t = st_realloc_array(m->tets, ntets, 4 * sizeof(uint32_t));
        if (!t)
            return st_error_set(err, ST_ENOMEM, NULL, 0,
                                "out of memory for %zu tets", ntets);
        m->tets = t;
        m->cap_tets = ntets;
    }
    return ST_OK;
}

/* The next capacity when n elements are full: doubling, at least 64. */
static size_t next_cap(size_t n)
{
    size_t c;
    if (n < 32)
        return 64;
    if (st_size_mul(&c, n, 2) != 0)
        return n + 1;   /* the allocation will then fail its own check */
    return c;
}

st_status st_tetmesh_add_point(st_tetmesh *m, const double p[3],
                               st_error *err)
{
    if (m->npoints >= UINT32_MAX)
        return st_error_set(err, ST_ELIMIT, NULL, 0,
                            "more than %lu mesh points",
                            (unsigned long)UINT32_MAX);
    if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "mesh point %zu is not finite", m->npoints);
    if (m->npoints == m->cap_points) {
        st_status s = st_tetmesh_reserve(m, next_cap(m->npoints), 0, err);
        if (s)
            return s;
    }
    double *q = m->xyz + 3 * m->npoints;
    q[0] = p[0];
    q[1] = p[1];
    q[2] = p[2];
    m->npoints++;
    return ST_OK;
}

st_status st_tetmesh_add_tet(st_tetmesh *m, uint32_t a, uint32_t b,
                             uint32_t c, uint32_t d, st_error *err)
{
    if (a >= m->npoints || b >= m->npoints || c >= m->npoints ||
        d >= m->npoints)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "tet %zu refers to point %lu of %zu", m->ntets,
                            (unsigned long)(a >= m->npoints   ? a
                                            : b >= m->npoints ? b
                                            : c >= m->npoints ? c
                                                              : d),
                            m->npoints);
    if (m->ntets == m->cap_tets) {
        st_status s = st_tetmesh_reserve(m, 0, next_cap(m->ntets), err);
        if (s)
            return s;
    }
    uint32_t *t = m->tets + 4 * m->ntets;
    t[0] = a;
    t[1] = b;
    t[2] = c;
    t[3] = d;
    m->ntets++;
    return ST_OK;
}

/* ---- arrays -------------------------------------------------------------- */

st_status st_tetmesh_add_array(st_tetmesh *m, const char *name,
                               st_tet_assoc assoc, int ncomp,
                               double **values, st_error *err)
{
    if (values)
        *values = NULL;
    if (!name || !*name)
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "a mesh array needs a name");
    if (ncomp < 1 || ncomp > 9 || (assoc != ST_ON_POINTS && assoc != ST_ON_CELLS))
        return st_error_set(err, ST_EINPUT, NULL, 0,
                            "mesh array '%s': %d components (1..9 allowed)",
                            name, ncomp);
    size_t n = assoc == ST_ON_POINTS ? m->npoints : m->ntets, total;
    if (st_size_mul(&total, n, (size_t)ncomp) != 0)
        return st_error_set(err, ST_ENOMEM, NULL, 0,
                            "mesh array '%s' is too large", name);
    double *v = st_calloc_array(total, sizeof(double));
    if (!v)
        return st_error_set(err, ST_ENOMEM, NULL, 0,
                            "out of memory for mesh array '%s'", name);
    for (size_t i = 0; i < m->narrays; i++) {
        st_tet_array *a = &m->arrays[i];
        if (a->assoc == assoc && strcmp(a->name, name) == 0) {
            free(a->values);
            a->values = v;
            a->ncomp = ncomp;
            if (values)
                *values = v;
            return ST_OK;
        }
    }
    char *nm = st_strdup(name);
    st_tet_array *arr = st_realloc_array(m->arrays, m->narrays + 1,
                                         sizeof(st_tet_array));
    if (!nm || !arr) {
        free(nm);
        free(v);
        if (arr)
            m->arrays = arr;
        return st_error_set(err, ST_ENOMEM, NULL, 0,
                            "out of memory for mesh array '%s'", name);
    }
    m->arrays = arr;
    arr[m->narrays].name = nm;
    arr[m->narrays].assoc = assoc;
    arr[m->narrays].ncomp = ncomp;
    arr[m->narrays].values = v;
    m->narrays++;
    if (values)
        *values = v;
    return ST_OK;
}

const st_tet_array *st_tetmesh_find_array(const st_tetmesh *m,
                                          const char *name,
                                          st_tet_assoc assoc)
{
    if (!m || !name)
        return NULL;
    for (size_t i = 0; i < m->narrays; i++)
        if (m->arrays[i].assoc == assoc &&
            strcmp(m->arrays[i].name, name) == 0)
            return &m->arrays[i];
    return NULL;
}

/* ---- copy and compaction ------------------------------------------------- */

st_status st_tetmesh_copy(st_tetmesh **out, const st_tetmesh *src,
                          st_error *err)
{
    *out = NULL;
    st_tetmesh *m = st_tetmesh_new();
    if (!m)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    st_status s = st_tetmesh_reserve(m, src->npoints, src->ntets, err);
    if (s)
        goto fail;
    if (src->npoints)
        memcpy(m->xyz, src->xyz, src->npoints * 3 * sizeof(double));
    if (src->ntets)
        memcpy(m->tets, src->tets, src->ntets * 4 * sizeof(uint32_t));
    m->npoints = src->npoints;
    m->ntets = src->ntets;
    for (size_t i = 0; i < src->narrays; i++) {
        const st_tet_array *a = &src->arrays[i];
        double *v;
        if ((s = st_tetmesh_add_array(m, a->name, a->assoc, a->ncomp, &v,
                                      err)))
            goto fail;
        size_t n = (a->assoc == ST_ON_POINTS ? m->npoints : m->ntets) *
                   (size_t)a->ncomp;
        if (n)
            memcpy(v, a->values, n * sizeof(double));
    }
    if (st_meta_copy(&m->meta, &src->meta)) {
        s = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
        goto fail;
    }
    *out = m;
    return ST_OK;
fail:
    st_tetmesh_free(m);
    return s;
}

st_status st_tetmesh_compact(st_tetmesh *m, st_error *err)
{
    if (m->npoints == 0)
        return ST_OK;
    uint32_t *map = st_malloc_array(m->npoints, sizeof(uint32_t));
    if (!map)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    const uint32_t unused = UINT32_MAX;
    for (size_t i = 0; i < m->npoints; i++)
        map[i] = unused;
    for (size_t i = 0; i < 4 * m->ntets; i++)
        map[m->tets[i]] = 0;
    /* New numbers in old order, so a compact mesh stays as it was. */
    size_t n = 0;
    for (size_t i = 0; i < m->npoints; i++)
        if (map[i] != unused)
            map[i] = (uint32_t)n++;
    if (n == m->npoints) {
        free(map);
        return ST_OK;
    }
    for (size_t i = 0; i < m->npoints; i++)
        if (map[i] != unused && map[i] != i)
            memcpy(m->xyz + 3 * (size_t)map[i], m->xyz + 3 * i,
                   3 * sizeof(double));
    for (size_t a = 0; a < m->narrays; a++) {
        st_tet_array *arr = &m->arrays[a];
        if (arr->assoc != ST_ON_POINTS)
            continue;
        size_t c = (size_t)arr->ncomp;
        for (size_t i = 0; i < m->npoints; i++)
            if (map[i] != unused && map[i] != i)
                memcpy(arr->values + c * map[i], arr->values + c * i,
                       c * sizeof(double));
    }
    for (size_t i = 0; i < 4 * m->ntets; i++)
        m->tets[i] = map[m->tets[i]];
    m->npoints = n;
    free(map);
    return ST_OK;
}

/* ---- adjacency ----------------------------------------------------------- */

typedef struct face_rec {
    uint32_t v1, v2;    /* the two larger indices, v1 <= v2 */
    uint64_t id;        /* 4 * tet + corner */
} face_rec;

static void sort3(uint32_t v[3])
{
    uint32_t t;
    if (v[0] > v[1]) { t = v[0]; v[0] = v[1]; v[1] = t; }
    if (v[1] > v[2]) { t = v[1]; v[1] = v[2]; v[2] = t; }
    if (v[0] > v[1]) { t = v[0]; v[0] = v[1]; v[1] = t; }
}

/* The faces' order: by v1, v2, then id (a total order: ids are unique). */
static int face_less(const face_rec *a, const face_rec *b)
{
    if (a->v1 != b->v1)
        return a->v1 < b->v1;
    if (a->v2 != b->v2)
        return a->v2 < b->v2;
    return a->id < b->id;
}

static void insertion_faces(face_rec *r, size_t n)
{
    for (size_t i = 1; i < n; i++) {
        face_rec x = r[i];
        size_t j = i;
        while (j > 0 && face_less(&x, &r[j - 1])) {
            r[j] = r[j - 1];
            j--;
        }
        r[j] = x;
    }
}

/* Sorts a bucket by face_less (a total order, so any sort gives the same
 * result): runs of 16 by insertion, then merged
 * through tmp (n records) with the comparison inlined, where qsort's
 * indirect calls were most of the fit's adjacency. */
static void sort_bucket(face_rec *r, face_rec *tmp, size_t n)
{
    enum { RUN = 16 };
    for (size_t i = 0; i < n; i += RUN)
        insertion_faces(r + i, n - i < RUN ? n - i : RUN);
    face_rec *src = r, *dst = tmp;
    for (size_t w = RUN; w < n; w *= 2) {
        for (size_t lo = 0; lo < n; lo += 2 * w) {
            size_t mid = lo + w < n ? lo + w : n, hi = lo + 2 * w < n ? lo + 2 * w : n;
            size_t i = lo, j = mid, k = lo;
            while (i < mid && j < hi)
                dst[k++] = face_less(&src[j], &src[i]) ? src[j++] : src[i++];
            while (i < mid)
                dst[k++] = src[i++];
            while (j < hi)
                dst[k++] = src[j++];
        }
        face_rec *t = src;
        src = dst;
        dst = t;
    }
    if (src != r)
        memcpy(r, src, n * sizeof *r);
}

/* nbr[4t+i]: neighbour tet, -1 boundary, -2 non-manifold face. */
static st_status adjacency(const st_tetmesh *m, int64_t **out,
                           size_t *nonmanifold, st_error *err)
{
    size_t nf;
    *out = NULL;
    *nonmanifold = 0;
    if (st_size_mul(&nf, m->ntets, 4) != 0)
        return st_error_set(err, ST_ENOMEM, NULL, 0, "mesh too large");
    int64_t *nbr = st_malloc_array(nf, sizeof(int64_t));
    face_rec *rec = st_malloc_array(nf, sizeof(face_rec));
    size_t *start = st_calloc_array(m->npoints + 1, sizeof(size_t));
    if (!nbr || !rec || !start) {
        free(nbr);
        free(rec);
        free(start);
        return st_error_set(err, ST_ENOMEM, NULL, 0,
                            "out of memory for the faces of %zu tets",
                            m->ntets);
    }
    /* Counting sort by smallest index. */
    for (size_t t = 0; t < m->ntets; t++)
        for (int i = 0; i < 4; i++) {
            const uint32_t *q = m->tets + 4 * t;
            uint32_t v[3] = {q[k_face[i][0]], q[k_face[i][1]],
                             q[k_face[i][2]]};
            sort3(v);
            start[v[0] + 1]++;
        }
    for (size_t i = 0; i < m->npoints; i++)
        start[i + 1] += start[i];
    size_t *fill = st_malloc_array(m->npoints + 1, sizeof(size_t));
    if (!fill) {
        free(nbr);
        free(rec);
        free(start);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    memcpy(fill, start, (m->npoints + 1) * sizeof(size_t));
    for (size_t t = 0; t < m->ntets; t++)
        for (int i = 0; i < 4; i++) {
            const uint32_t *q = m->tets + 4 * t;
            uint32_t v[3] = {q[k_face[i][0]], q[k_face[i][1]],
                             q[k_face[i][2]]};
            sort3(v);
            face_rec *r = &rec[fill[v[0]]++];
            r->v1 = v[1];
            r->v2 = v[2];
            r->id = 4 * (uint64_t)t + (uint64_t)i;
        }
    free(fill);
    size_t nm = 0, most = 1;
    for (size_t b = 0; b < m->npoints; b++)
        most = start[b + 1] - start[b] > most ? start[b + 1] - start[b] : most;
    face_rec *tmp = st_malloc_array(most, sizeof *tmp);
    if (!tmp) {
        free(nbr);
        free(rec);
        free(start);
        return st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
    }
    for (size_t b = 0; b < m->npoints; b++) {
        face_rec *r = rec + start[b];
        size_t n = start[b + 1] - start[b];
        sort_bucket(r, tmp, n);
        for (size_t i = 0; i < n;) {
            size_t j = i + 1;
            while (j < n && r[j].v1 == r[i].v1 && r[j].v2 == r[i].v2)
                j++;
            if (j - i == 1) {
                nbr[r[i].id] = -1;
            } else if (j - i == 2) {
                nbr[r[i].id] = (int64_t)(r[i + 1].id / 4);
                nbr[r[i + 1].id] = (int64_t)(r[i].id / 4);
            } else {
                nm++;
                for (size_t k = i; k < j; k++)
                    nbr[r[k].id] = -2;
            }
            i = j;
        }
    }
    free(tmp);
    free(rec);
    free(start);
    *out = nbr;
    *nonmanifold = nm;
    return ST_OK;
}

st_status st_tetmesh_neighbors(const st_tetmesh *m, int64_t **nbr,
                               size_t *nonmanifold_faces, st_error *err)
{
    size_t nm;
    st_status s = adjacency(m, nbr, &nm, err);
    if (s)
        return s;
    for (size_t i = 0; i < 4 * m->ntets; i++)
        if ((*nbr)[i] == -2)
            (*nbr)[i] = -1;
    if (nonmanifold_faces)
        *nonmanifold_faces = nm;
    return ST_OK;
}

st_status st_tetmesh_boundary(const st_tetmesh *m, uint32_t **faces,
                              uint32_t **face_tet, size_t *nfaces,
                              st_error *err)
{
    *faces = NULL;
    if (face_tet)
        *face_tet = NULL;
    *nfaces = 0;
    if (m->ntets > UINT32_MAX)
        return st_error_set(err, ST_ELIMIT, NULL, 0,
                            "more than %lu tets", (unsigned long)UINT32_MAX);
    int64_t *nbr;
    size_t nm;
    st_status s = adjacency(m, &nbr, &nm, err);
    if (s)
        return s;
    size_t n = 0;
    for (size_t i = 0; i < 4 * m->ntets; i++)
        n += nbr[i] == -1;
    uint32_t *f = st_malloc_array(n, 3 * sizeof(uint32_t));
    uint32_t *ft = face_tet ? st_malloc_array(n, sizeof(uint32_t)) : NULL;
    if (!f || (face_tet && !ft)) {
        free(f);
        free(ft);
        free(nbr);
        return st_error_set(err, ST_ENOMEM, NULL, 0,
                            "out of memory for %zu boundary faces", n);
    }
    size_t k = 0;
    for (size_t t = 0; t < m->ntets; t++)
        for (int i = 0; i < 4; i++) {
            if (nbr[4 * t + (size_t)i] != -1)
                continue;
            const uint32_t *q = m->tets + 4 * t;
            f[3 * k] = q[k_face[i][0]];
            f[3 * k + 1] = q[k_face[i][1]];
            f[3 * k + 2] = q[k_face[i][2]];
            if (ft)
                ft[k] = (uint32_t)t;
            k++;
        }
    free(nbr);
    *faces = f;
    if (face_tet)
        *face_tet = ft;
    *nfaces = n;
    return ST_OK;
}

st_status st_tetmesh_boundary_soup(struct st_soup **out, const st_tetmesh *m,
                                   st_error *err)
{
    *out = NULL;
    uint32_t *f = NULL, *ft = NULL, *map = NULL;
    size_t nf = 0;
    st_status rc = st_tetmesh_boundary(m, &f, &ft, &nf, err);
    if (rc)
        return rc;
    st_soup *s = st_soup_new();
    map = st_malloc_array(m->npoints ? m->npoints : 1, sizeof *map);
    if (!s || !map) {
        rc = st_error_set(err, ST_ENOMEM, NULL, 0, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < m->npoints; i++)
        map[i] = UINT32_MAX;
    for (size_t k = 0; k < nf; k++) {
        uint32_t *v = f + 3 * k;
        const uint32_t *q = m->tets + 4 * (size_t)ft[k];
        uint32_t opp = q[0] ^ q[1] ^ q[2] ^ q[3] ^ v[0] ^ v[1] ^ v[2];
        /* The fourth point behind the face: orient3d > 0 (pred.h). */
        if (st_orient3d(m->xyz + 3 * (size_t)v[0], m->xyz + 3 * (size_t)v[1],
                        m->xyz + 3 * (size_t)v[2], m->xyz + 3 * (size_t)opp) < 0) {
            uint32_t tmp = v[1];
            v[1] = v[2];
            v[2] = tmp;
        }
        uint32_t w[3];
        for (int c = 0; c < 3; c++) {
            if (map[v[c]] == UINT32_MAX) {
                const double *p = m->xyz + 3 * (size_t)v[c];
                if ((rc = st_soup_add_vertex(s, p[0], p[1], p[2], err)))
                    goto done;
                map[v[c]] = (uint32_t)(s->nverts - 1);
            }
            w[c] = map[v[c]];
        }
        if ((rc = st_soup_add_triangle(s, w[0], w[1], w[2], err)))
            goto done;
    }
    *out = s;
    s = NULL;
done:
    st_soup_free(s);
    free(map);
    free(f);
    free(ft);
    return rc;
}

/* ---- quality ------------------------------------------------------------- */

void st_tetmesh_quality(const st_tetmesh *m, double *min_deg,
                        double *max_deg, double *volume)
{
    const long long n = (long long)m->ntets;
#pragma omp parallel for schedule(static) if (n > 4096)
    for (long long t = 0; t < n; t++) {
        const uint32_t *q = m->tets + 4 * (size_t)t;
        const double *p0 = m->xyz + 3 * (size_t)q[0];
        const double *p1 = m->xyz + 3 * (size_t)q[1];
        const double *p2 = m->xyz + 3 * (size_t)q[2];
        const double *p3 = m->xyz + 3 * (size_t)q[3];
        if (min_deg || max_deg) {
            double lo, hi;
            st_tet_dihedral_range(p0, p1, p2, p3, &lo, &hi);
            if (min_deg)
                min_deg[t] = lo;
            if (max_deg)
                max_deg[t] = hi;
        }
        if (volume)
            volume[t] = st_tet_volume(p0, p1, p2, p3);
    }
}
