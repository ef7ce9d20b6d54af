/* What the report's plots show, read back from their pixels: a method keeps
 * its colour when rows are added; the m_sL2-by-distance plot shows a method
 * a thousand times better than the worst off its floor and draws no line
 * across distances without pairs; the yaw plot draws -3° beside 0°, not at
 * 357°. Geometry of the frame (reports/chart.c): plot area x 84…650, y
 * 78…516; legend swatches from x 676, 28 px wide, the first at y 114, then
 * every 24 px. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <cairo.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fake_run.h"
#include "reports/chart.h"
#include "tcb/config.h"
#include "tcb/fsutil.h"
#include "tcb/report.h"
#include "testutil.h"

enum { PX0 = 84, PX1 = 650, PY0 = 78, PY1 = 516, SWATCH_X = 676, SWATCH_Y = 114, SWATCH_STEP = 24 };

typedef struct rgb {
    int r, g, b;
} rgb;

typedef struct image {
    cairo_surface_t *s;
    int w, h, stride;
    const unsigned char *data;
} image;

static image load_png(const char *path)
{
    image im = {cairo_image_surface_create_from_png(path), 0, 0, 0, NULL};
    if (cairo_surface_status(im.s) != CAIRO_STATUS_SUCCESS) fail_msg("%s: not a PNG cairo reads", path);
    im.w = cairo_image_surface_get_width(im.s), im.h = cairo_image_surface_get_height(im.s);
    im.stride = cairo_image_surface_get_stride(im.s);
    im.data = cairo_image_surface_get_data(im.s);
    return im;
}

static rgb pixel(const image *im, int x, int y)
{
    uint32_t v = *(const uint32_t *)(im->data + (size_t)y * im->stride + 4 * (size_t)x);
    return (rgb){(int)(v >> 16 & 255), (int)(v >> 8 & 255), (int)(v & 255)};
}

static int same(rgb a, rgb b) { return a.r == b.r && a.g == b.g && a.b == b.b; }

/* Not white, grey or black: a series' colour (the palette has no grey but
 * one, which these tests' labels do not draw). */
static int saturated(rgb c)
{
    int hi = c.r > c.g ? (c.r > c.b ? c.r : c.b) : (c.g > c.b ? c.g : c.b);
    int lo = c.r < c.g ? (c.r < c.b ? c.r : c.b) : (c.g < c.b ? c.g : c.b);
    return hi - lo > 40;
}

/* The colour of legend row k's swatch: its most saturated pixel on the
 * swatch's line (a dash pattern leaves gaps, never the whole line). */
static rgb swatch(const image *im, int k)
{
    int y = SWATCH_Y + SWATCH_STEP * k;
    for (int x = SWATCH_X; x < SWATCH_X + 28; x++)
        if (saturated(pixel(im, x, y))) return pixel(im, x, y);
    fail_msg("legend row %d has no coloured swatch", k);
    return (rgb){0, 0, 0};
}

/* Pixels of colour c in column x of the plot area. */
static int in_column(const image *im, int x, rgb c, int *y_min, int *y_max)
{
    int n = 0;
    *y_min = PY1, *y_max = PY0;
    for (int y = PY0; y <= PY1; y++)
        if (same(pixel(im, x, y), c)) {
            n++;
            *y_min = y < *y_min ? y : *y_min, *y_max = y > *y_max ? y : *y_max;
        }
    return n;
}

static void write_run(const char *dir, const char *const *methods, const double *base, int n)
{
    for (int k = 0; k < n; k++) {
        fake_cell c = {"anim", "horse", "test", methods[k], 0, TCB_CELL_OK, base[k], 1, 0};
        assert_int_equal(fake_write(dir, &c), 0);
    }
    tcb_error err = {0};
    if (tcb_report_write(dir, NULL, NULL, &err)) fail_msg("%s", err.msg);
}

static image report_png(const char *dir, const char *kind)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/report/%s_anim_horse.png", dir, kind);
    return load_png(path);
}

/* Rows B and C alone, then with A, which sorts before them and moves them
 * down the legend: their colours stay, in the PCK and the gap plot. */
static void test_colour_follows_the_label(void **state)
{
    (void)state;
    char two[512], three[512];
    tu_make_tmpdir(two, sizeof two);
    tu_make_tmpdir(three, sizeof three);
    static const char *const bc[] = {"nearest", "nricp"}, *const abc[] = {"atlasnet", "nearest", "nricp"};
    static const double base[] = {0.01, 0.02, 0.03};
    write_run(two, bc, base, 2);
    write_run(three, abc, base, 3);
    static const char *const kinds[] = {"pck", "gap"};
    for (int k = 0; k < 2; k++) {
        image a = report_png(two, kinds[k]), b = report_png(three, kinds[k]);
        assert_true(same(swatch(&a, 0), swatch(&b, 1)));
        assert_true(same(swatch(&a, 1), swatch(&b, 2)));
        /* and the shipped labels differ (the salt's promise) */
        assert_false(same(swatch(&b, 0), swatch(&b, 1)) || same(swatch(&b, 1), swatch(&b, 2)) ||
                     same(swatch(&b, 0), swatch(&b, 2)));
        cairo_surface_destroy(a.s), cairo_surface_destroy(b.s);
    }
    tu_remove_tree(two), tu_remove_tree(three);
}

/* Distinct keys: colours up to 10 labels, colour-and-dash pairs beyond. */
static int distinct_styles(const int *style, int n)
{
    int modulus = n <= 10 ? 10 : 40;
    for (int a = 0; a < n; a++)
        for (int b = a + 1; b < n; b++)
            if (style[a] % modulus == style[b] % modulus) return 0;
    return 1;
}

/* Within each shipped config the method labels have distinct colours
 * (distinct colour-and-dash pairs where there are more than ten). */
static void check_config_styles(const char *path, void *arg)
{
    (void)arg;
    tcb_config c;
    tcb_error err = {0};
    if (tcb_config_load(path, &c, &err)) fail_msg("%s", err.msg);
    const char **label = malloc(sizeof *label * (size_t)c.n_methods);
    int *style = malloc(sizeof *style * (size_t)c.n_methods);
    assert_non_null(label), assert_non_null(style);
    for (int k = 0; k < c.n_methods; k++) label[k] = c.methods[k].label;
    tcb_chart_styles(label, c.n_methods, style);
    int ok = distinct_styles(style, c.n_methods);
    free(label), free(style), tcb_config_free(&c);
    if (!ok) fail_msg("%s: two labels share a style", path);
}

static void test_shipped_labels_have_their_own_colours(void **state)
{
    (void)state;
    assert_true(tu_for_each_json(TCB_SOURCE_DIR "/configs", check_config_styles, NULL) >= 10);
}

/* "atlasnet" and "pdg" hash to one colour: the first in strcmp order keeps
 * it, whatever the order given, and the other takes the next free one. */
static void test_a_collision_moves_the_later_label(void **state)
{
    (void)state;
    assert_int_equal(tcb_chart_style_of("atlasnet") % 10, tcb_chart_style_of("pdg") % 10);
    const char *const ab[] = {"pdg", "atlasnet"};
    int style[2];
    tcb_chart_styles(ab, 2, style);
    assert_int_equal(style[1], tcb_chart_style_of("atlasnet"));
    assert_int_equal(style[0] % 10, (tcb_chart_style_of("pdg") + 1) % 10);
    assert_int_equal(style[0] / 10, tcb_chart_style_of("pdg") / 10); /* its dash stays */
}

/* Random label sets of 1 … 40: distinct styles always; each label its own
 * style whenever the own keys were distinct already. */
static void test_random_label_sets_never_share(void **state)
{
    (void)state;
    char names[40][16];
    const char *label[40];
    int style[40], own[40];
    unsigned x = 12345u;
    for (int trial = 0; trial < 2000; trial++) {
        int n = 1 + trial % 40;
        for (int k = 0; k < n; k++) {
            x = x * 1103515245u + 12345u;
            snprintf(names[k], sizeof names[k], "m%d_%u", k, x >> 8);
            label[k] = names[k];
            own[k] = tcb_chart_style_of(label[k]);
        }
        tcb_chart_styles(label, n, style);
        assert_true(distinct_styles(style, n));
        if (distinct_styles(own, n))
            for (int k = 0; k < n; k++) assert_int_equal(style[k], own[k]);
    }
}

/* Pair 1 moved from |i - j| = 2 to 4: distances 2 and 3 have no pairs. */
static void move_pair_to_gap_4(cJSON *root, const void *arg)
{
    (void)arg;
    cJSON *pair = cJSON_GetArrayItem(cJSON_GetObjectItem(root, "pairs"), 1);
    assert_int_equal(cJSON_GetArrayItem(pair, 0)->valueint - cJSON_GetArrayItem(pair, 1)->valueint, 2);
    cJSON_ReplaceItemInArray(pair, 0, cJSON_CreateNumber(cJSON_GetArrayItem(pair, 1)->valueint + 4));
}

/* nricp errs 500 times less than nearest: on an axis scaled to the worst
 * it would lie within a pixel of the floor; on the log axis it is well off
 * it. Between distance 1 and 4 nothing was measured: no pixel of either
 * line at distance 2.5. */
static void test_gap_plot_shows_the_best_and_skips_holes(void **state)
{
    (void)state;
    char dir[512];
    tu_make_tmpdir(dir, sizeof dir);
    static const char *const methods[] = {"nearest", "nricp"};
    static const double base[] = {1.0, 0.002};
    for (int k = 0; k < 2; k++) {
        fake_cell c = {"anim", "horse", "test", methods[k], 0, TCB_CELL_OK, base[k], 1, 0};
        assert_int_equal(fake_write(dir, &c), 0);
        assert_int_equal(fake_edit(dir, &c, move_pair_to_gap_4, NULL), 0);
    }
    tcb_error err = {0};
    if (tcb_report_write(dir, NULL, NULL, &err)) fail_msg("%s", err.msg);
    image im = report_png(dir, "gap");
    rgb good = swatch(&im, 1);
    int lo, hi, x1 = PX0 + (PX1 - PX0) / 4; /* distance 1 of 0…4 */
    assert_true(in_column(&im, x1, good, &lo, &hi) > 0);
    assert_true(hi < PY1 - 30);
    assert_int_equal(in_column(&im, PX0 + (PX1 - PX0) * 5 / 8, good, &lo, &hi), 0);
    assert_int_equal(in_column(&im, PX0 + (PX1 - PX0) * 5 / 8, swatch(&im, 0), &lo, &hi), 0);
    cairo_surface_destroy(im.s);
    tu_remove_tree(dir);
}

/* Steps 0, 119, 0 (0°, 357°, 0°): frame 1 drawn 3° under the 0° line, in
 * the middle of the -180…180 axis, not near its top. */
static void test_yaw_plot_in_plus_minus_180(void **state)
{
    (void)state;
    char dir[512], path[1024];
    tu_make_tmpdir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/yaw.png", dir);
    static const int steps[] = {0, 119, 0};
    tcb_error err = {0};
    if (tcb_plot_yaw(path, "walk", steps, 3, 100, &err)) fail_msg("%s", err.msg);
    image im = load_png(path);
    int x = (PX0 + PX1) / 2;
    double zero = (PY0 + PY1) / 2.0, minus3 = zero + (PY1 - PY0) * 3.0 / 360.0;
    assert_true(saturated(pixel(&im, x, (int)(minus3 + 0.5))));
    for (int y = PY0; y < zero - 20; y++) assert_false(saturated(pixel(&im, x, y)));
    cairo_surface_destroy(im.s);
    tu_remove_tree(dir);
}

/* Fontconfig, which cairo uses to find fonts, keeps its configuration until
 * FcFini, which nothing calls at exit: not a leak of ours. */
const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void) { return "leak:libfontconfig.so\n"; }

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_colour_follows_the_label),
        cmocka_unit_test(test_shipped_labels_have_their_own_colours),
        cmocka_unit_test(test_a_collision_moves_the_later_label),
        cmocka_unit_test(test_random_label_sets_never_share),
        cmocka_unit_test(test_gap_plot_shows_the_best_and_skips_holes),
        cmocka_unit_test(test_yaw_plot_in_plus_minus_180),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
