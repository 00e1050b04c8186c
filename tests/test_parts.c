/*
 * test_parts.c - parts.h: the readers' named runs (OBJ o and g, STL solid
 * NAME, glTF mesh nodes), the split by names (empty runs skipped, unnamed
 * and non-UTF-8 names by index, duplicates suffixed without meeting a given
 * name) and by pieces, and the tagging of a nested pair of cubes.
 */
#include "souptet/parts.h"
#include "souptet/pipeline.h"
#include "tap.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static st_soup *parse(st_soup_format f, const char *text)
{
    st_soup *s = NULL;
    st_error err;
    st_error_clear(&err);
    if (st_soup_parse(&s, f, (const unsigned char *)text, strlen(text), "t", &err)) {
        TAP_NOTE("parse: %s", err.msg);
        return NULL;
    }
    return s;
}

static void test_obj_names(void)
{
    const char *obj =
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
        "f 1 2 3\n"                       /* before any name: unnamed */
        "o  a  \nf 1 2 4\n"                /* blanks trimmed */
        "o empty\n"
        "o a\ng g1\nf 1 3 4\nf 2 3 4\n"    /* a duplicate */
        "o a_2\nf 1 2 3\n";                /* a given name the suffix avoids */
    st_soup *s = parse(ST_SOUP_OBJ, obj);
    TAP_CHECK(s && s->nnames == 5, "OBJ: 5 named runs (4 o, 1 g)");
    if (!s)
        return;
    TAP_CHECK(strcmp(s->names[0].name, "a") == 0 && s->names[0].first == 1 &&
                  s->names[0].level == 1, "OBJ: 'o  a  ' is 'a' from triangle 1");
    TAP_CHECK(s->names[3].level == 2 && strcmp(s->names[3].name, "g1") == 0,
              "OBJ: g is level 2");
    st_parts p;
    st_error err;
    st_error_clear(&err);
    TAP_CHECK(st_parts_split(&p, s, ST_PARTS_AUTO, &err) == ST_OK, "split: ok (%s)", err.msg);
    TAP_CHECK(p.mode == ST_PARTS_NAMES && p.nparts == 4, "auto: names, 4 parts (%zu)", p.nparts);
    if (p.nparts == 4) {
        TAP_CHECK(strcmp(p.names[0], "part_0") == 0 && strcmp(p.names[1], "a") == 0 &&
                      strcmp(p.names[2], "a_3") == 0 && strcmp(p.names[3], "a_2") == 0,
                  "names part_0 a a_3 a_2 (%s %s %s %s)", p.names[0], p.names[1], p.names[2],
                  p.names[3]);
        TAP_CHECK(p.tri_part[0] == 0 && p.tri_part[1] == 1 && p.tri_part[2] == 2 &&
                      p.tri_part[3] == 2 && p.tri_part[4] == 3, "each triangle's part");
        TAP_CHECK(p.tris_of[2] == 2, "part a_3 has 2 triangles");
    }
    TAP_CHECK(p.empty == 1 && strcmp(p.first_empty, "empty") == 0, "one empty run said");
    TAP_CHECK(p.unnamed == 1 && p.duplicates == 1 && p.not_utf8 == 0, "unnamed 1, duplicate 1");
    st_parts_free(&p);
    st_parts_free(&p);   /* safe twice */
    st_soup_free(s);
}

static void test_groups_utf8_stl(void)
{
    st_soup *s = parse(ST_SOUP_OBJ, "v 0 0 0\nv 1 0 0\nv 0 1 0\ng caf\xc3\xa9\nf 1 2 3\n"
                                    "g bad\xe9\nf 1 3 2\ng \xed\xa0\x80\nf 2 1 3\n");
    st_parts p;
    st_error err;
    st_error_clear(&err);
    TAP_CHECK(s && st_parts_split(&p, s, ST_PARTS_NAMES, &err) == ST_OK, "groups: split");
    if (s && p.nparts == 3) {
        TAP_CHECK(strcmp(p.names[0], "caf\xc3\xa9") == 0 && strcmp(p.names[1], "part_1") == 0 &&
                      strcmp(p.names[2], "part_2") == 0,
                  "UTF-8 kept; a Latin-1 byte and a surrogate named by index");
        TAP_CHECK(p.not_utf8 == 2, "2 names not UTF-8");
    } else {
        TAP_CHECK(0, "groups: 3 parts");
    }
    st_parts_free(&p);
    st_soup_free(s);

    const char *stl =
        "solid left one\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
        "vertex 0 1 0\nendloop\nendfacet\nendsolid left one\n"
        "solid\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
        "vertex 0 1 0\nendloop\nendfacet\nendsolid\n";
    s = parse(ST_SOUP_STL, stl);
    TAP_CHECK(s && st_parts_split(&p, s, ST_PARTS_AUTO, &err) == ST_OK && p.nparts == 2 &&
                  strcmp(p.names[0], "left one") == 0 && strcmp(p.names[1], "part_1") == 0,
              "STL: solid names, an unnamed solid by index");
    st_parts_free(&p);
    st_soup_free(s);

    /* a bare "solid" names nothing: auto takes the pieces */
    s = parse(ST_SOUP_STL, "solid\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                           "vertex 0 1 0\nendloop\nendfacet\nfacet normal 0 0 1\nouter loop\n"
                           "vertex 5 0 0\nvertex 6 0 0\nvertex 5 1 0\nendloop\nendfacet\n"
                           "endsolid\n");
    TAP_CHECK(s && st_parts_split(&p, s, ST_PARTS_AUTO, &err) == ST_OK &&
                  p.mode == ST_PARTS_PIECES && p.nparts == 2,
              "STL with a bare solid, auto: 2 pieces");
    st_parts_free(&p);
    st_soup_free(s);
}

/* Two disjoint tetrahedra's surfaces, and a degenerate triangle on one. */
static void test_pieces(void)
{
    st_soup *s = parse(ST_SOUP_OFF, "OFF\n8 9 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
                                    "5 0 0\n6 0 0\n5 1 0\n5 0 1\n"
                                    "3 4 6 5\n3 4 5 7\n3 4 7 6\n3 5 6 7\n"
                                    "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n3 0 0 1\n");
    st_parts p;
    st_error err;
    st_error_clear(&err);
    TAP_CHECK(s && st_parts_split(&p, s, ST_PARTS_AUTO, &err) == ST_OK, "pieces: split");
    if (s && p.nparts == 2) {
        TAP_CHECK(p.mode == ST_PARTS_PIECES, "auto without names: pieces");
        TAP_CHECK(p.tri_part[0] == 0 && p.tri_part[4] == 1 && p.tri_part[8] == 1,
                  "pieces numbered by first triangle; the degenerate joins its corner's");
        TAP_CHECK(strcmp(p.names[1], "piece_1") == 0, "named piece_K");
    } else {
        TAP_CHECK(0, "pieces: 2 parts");
    }
    st_parts_free(&p);
    st_soup_free(s);
}

/* A cube [0,4]^3 around a cube [1.5,2.5]^3, meshed at 8 cells. */
static void test_tag_nested(void)
{
    char obj[2048];
    int n = 0;
    const double box[2][2] = {{0, 4}, {1.5, 2.5}};
    for (int b = 0; b < 2; b++) {
        n += snprintf(obj + n, sizeof obj - (size_t)n, "o %s\n", b ? "inner" : "outer");
        for (int k = 0; k < 8; k++)
            n += snprintf(obj + n, sizeof obj - (size_t)n, "v %g %g %g\n", box[b][k & 1],
                          box[b][(k >> 1) & 1], box[b][(k >> 2) & 1]);
        static const int q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                    {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
        for (int f = 0; f < 6; f++)
            n += snprintf(obj + n, sizeof obj - (size_t)n, "f %d %d %d %d\n", 8 * b + q[f][0] + 1,
                          8 * b + q[f][1] + 1, 8 * b + q[f][2] + 1, 8 * b + q[f][3] + 1);
    }
    st_soup *s = parse(ST_SOUP_OBJ, obj);
    st_parts p;
    st_error err;
    st_error_clear(&err);
    if (!s || st_parts_split(&p, s, ST_PARTS_NAMES, &err)) {
        TAP_CHECK(0, "nested: split (%s)", err.msg);
        st_soup_free(s);
        return;
    }
    st_pipeline_params pp = st_pipeline_params_default();
    pp.cells = 8;
    pp.parts = &p;
    st_pipeline_stats st;
    st_tetmesh *m = NULL;
    TAP_CHECK(st_pipeline_run(&m, &st, s, &pp, NULL, &err) == ST_OK, "nested: run (%s)",
              err.msg);
    const st_tet_array *pa = m ? st_tetmesh_find_array(m, "part", ST_ON_CELLS) : NULL;
    const st_tet_array *sa = m ? st_tetmesh_find_array(m, "part_share", ST_ON_CELLS) : NULL;
    TAP_CHECK(pa && sa, "the part and part_share arrays");
    if (pa && sa) {
        size_t in_inner = 0, tagged_inner = 0;
        for (size_t t = 0; t < m->ntets; t++) {
            double c[3] = {0, 0, 0};
            for (int q = 0; q < 4; q++)
                for (int a = 0; a < 3; a++)
                    c[a] += 0.25 * m->xyz[3 * m->tets[4 * t + q] + a];
            int inside = 1;
            for (int a = 0; a < 3; a++)
                inside &= c[a] > 1.5 && c[a] < 2.5;
            in_inner += (size_t)inside;
            tagged_inner += (size_t)(inside && pa->values[t] == 1);
        }
        TAP_CHECK(in_inner > 0 && tagged_inner * 10 >= in_inner * 9,
                  "tets centred in the inner cube are tagged inner (%zu of %zu)", tagged_inner,
                  in_inner);
        TAP_CHECK(st.parts.nparts == 2 && st.parts.tets[1] > 0 &&
                      st.parts.volume[1] > 0.5 && st.parts.volume[1] < 2.0,
                  "the inner part's tagged volume %.3f within 0.5..2 of 1",
                  st.parts.nparts == 2 ? st.parts.volume[1] : -1.0);
        TAP_CHECK(st.parts.pseudo_volume[0] > 60 && st.parts.pseudo_volume[0] < 70,
                  "the outer part's pseudo volume %.2f is its solid's (64)",
                  st.parts.pseudo_volume[0]);
        const char **names = NULL;
        size_t np = 0;
        TAP_CHECK(st_parts_of_mesh(&names, &np, m, &err) == ST_OK && np == 2 && names[1] &&
                      strcmp(names[1], "inner") == 0, "the names in the mesh's meta");
        free((void *)names);
    }
    st_parts_tag_stats_free(&st.parts);
    free(st.candidates);
    st_tetmesh_free(m);
    st_parts_free(&p);
    st_soup_free(s);
}

static void test_mode_names(void)
{
    TAP_CHECK(st_parts_mode_from_name("pieces") == ST_PARTS_PIECES &&
                  st_parts_mode_from_name("colour") == -1 &&
                  strcmp(st_parts_mode_name(ST_PARTS_AUTO), "auto") == 0,
              "mode names both ways");
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(obj_names), TAP_TEST(groups_utf8_stl),
                                     TAP_TEST(pieces), TAP_TEST(tag_nested),
                                     TAP_TEST(mode_names), {0}};
    return tap_main(argc, argv, tests);
}
