/*
 * test_defaults.c - the library's defaults that the tools document.
 *
 * Run alone (TAP): the defaults soupmesh's pipeline takes agree with those
 * the separate tools take, so that the pipe of soupmesh(1) and the README
 * makes soupmesh's mesh (the field's resolution is soupdist's default, the
 * offset, fit iterations and quality pass are tetsmooth --fit's, the hole
 * caps and shells are soupsign's).
 *
 * With --print: one "tool.option value" line per default that a tool's
 * --help and man page state, read from the library (what the code does),
 * for tests/tools/docs.t to compare with the text.
 */
#include "souptet/dist.h"
#include "souptet/pipeline.h"
#include "souptet/pseudo.h"
#include "souptet/sign.h"
#include "souptet/smooth.h"
#include "souptet/wrap.h"
#include "tap.h"

#include <stdio.h>
#include <string.h>

static const char *onoff(int v)
{
    return v ? "on" : "off";
}

static void print_defaults(void)
{
    st_pipeline_params pl = st_pipeline_params_default();
    st_fit_params fit = st_fit_params_default();
    st_fair_params fair = st_fair_params_default();
    st_dist_params dist = st_dist_params_default();
    st_sign_params sign = st_sign_params_default();
    st_pseudo_params ps = st_pseudo_params_default();
    st_sign_refine_params ref = st_sign_refine_params_default();
    st_wrap_params wr = st_wrap_params_default();

    printf("soupmesh --cells %zu\n", pl.cells);
    printf("soupmesh --offset %.17g\n", pl.offset_ratio);
    printf("soupmesh --tries %zu\n", pl.tries);
    printf("soupmesh --seed %llu\n", (unsigned long long)pl.seed);
    printf("soupmesh --max-iters %d\n", pl.fit_max_iters ? pl.fit_max_iters : fit.max_iters);
    printf("soupmesh --fill-holes %s\n", onoff(pl.fill_holes));
    printf("soupmesh --shells %s\n", onoff(pl.closed_shells));

    printf("tetsmooth --iters %d\n", fair.iters);
    printf("tetsmooth --lambda %.17g\n", fair.lambda_dt);
    printf("tetsmooth --min-angle %.17g\n", fair.min_angle);
    printf("tetsmooth --offset %.17g\n", fit.offset_ratio);
    printf("tetsmooth --step %.17g\n", fit.step);
    printf("tetsmooth --max-iters %d\n", fit.max_iters);
    printf("tetsmooth --quality-rounds %d\n", fit.quality_rounds);

    printf("soupdist --voxels %zu\n", dist.cells);
    printf("soupdist --band %.17g\n", dist.band);

    printf("soupsign -k %.17g\n", sign.k);
    printf("soupsign --rays %d\n", sign.rays);
    printf("soupsign --refine-band %.17g\n", ref.band_voxels);
    printf("soupsign --refine-radius %d\n", ref.radius);
    printf("soupsign --refine-answers %d\n", ref.answers);
    printf("soupsign --fill-holes %s\n", onoff(ps.fill_holes));
    printf("soupsign --shells %s\n", onoff(ps.closed_shells));

    printf("soupwrap --iso %.17g\n", wr.iso);
    printf("soupwrap --adaptivity %.17g\n", wr.adaptivity);
    printf("soupwrap --smooth %d\n", wr.smooth);
    printf("soupwrap --min-volume %.17g\n", wr.min_volume);
    printf("soupwrap --fill-holes %s\n", onoff(ps.fill_holes));
    printf("soupwrap --shells %s\n", onoff(ps.closed_shells));
    printf("soupwrap --voxels %zu\n", dist.cells);
}

/* The defaults the tools share agree. */
static void test_shared(void)
{
    st_pipeline_params pl = st_pipeline_params_default();
    st_fit_params fit = st_fit_params_default();
    st_dist_params dist = st_dist_params_default();
    st_pseudo_params ps = st_pseudo_params_default();

    /* soupmesh's field: max(8 cells, min(16 cells, 128)) voxels
     * (pipeline.c); soupdist's default -r must be that at the default cells
     * for the pipe. */
    size_t field = pl.cells * 16 < 128 ? pl.cells * 16 : 128;
    field = pl.cells * 8 > field ? pl.cells * 8 : field;
    TAP_CHECK(dist.cells == field,
              "soupdist's default resolution (%zu) is soupmesh's field at %zu cells (%zu)",
              dist.cells, pl.cells, field);
    TAP_CHECK(pl.field_cells == 0, "soupmesh's field follows its cells by default");
    TAP_CHECK(pl.offset_ratio == fit.offset_ratio,
              "soupmesh --offset and tetsmooth --offset share a default (%g, %g)",
              pl.offset_ratio, fit.offset_ratio);
    TAP_CHECK(pl.fit_max_iters == 0, "soupmesh's fit stops where tetsmooth's does (%d)",
              fit.max_iters);
    TAP_CHECK(pl.quality == fit.quality, "both run the quality pass by default");
    TAP_CHECK(pl.fill_holes == ps.fill_holes && pl.closed_shells == ps.closed_shells,
              "soupmesh's pseudo volume is soupsign's (hole caps %d/%d, shells %d/%d)",
              pl.fill_holes, ps.fill_holes, pl.closed_shells, ps.closed_shells);
    TAP_CHECK(pl.seed == 1, "soupmesh's seed is 1, latticetet --sculpt's default");
    TAP_CHECK(pl.tries == 1, "soupmesh runs one candidate by default, as the pipe does");
    TAP_CHECK(pl.density_rho == 0 && pl.target_tets == 0 && pl.h == 0,
              "soupmesh sculpts at --cells by default");
}

int main(int argc, char **argv)
{
    static const tap_test tests[] = {TAP_TEST(shared), {0}};
    if (argc > 1 && strcmp(argv[1], "--print") == 0) {
        print_defaults();
        return 0;
    }
    return tap_main(argc, argv, tests);
}
