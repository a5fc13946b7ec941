/* PNG stimuli: decoding to relative luminance (sRGB transfer, Rec.709 weights, alpha), refusal
 * of damaged files, an image drawn as luminance around the mean, and a cairo text screen. */
#include <math.h>
#include <png.h>
#include <string.h>

#include "stim_test.h"
#include "tests/check.h"

static double srgb_decode(double v) { return v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4); }

/* Encodes w x h pixels of the given libpng simplified format into a malloc'd PNG. */
static unsigned char *encode(const void *px, int w, int h, png_uint_32 format, size_t *len)
{
    png_image im;
    memset(&im, 0, sizeof im);
    im.version = PNG_IMAGE_VERSION;
    im.width = (png_uint_32)w;
    im.height = (png_uint_32)h;
    im.format = format;
    png_alloc_size_t n = 0;
    if (!png_image_write_to_memory(&im, NULL, &n, 0, px, 0, NULL)) return NULL;
    unsigned char *buf = malloc(n);
    if (!png_image_write_to_memory(&im, buf, &n, 0, px, 0, NULL)) {
        free(buf);
        return NULL;
    }
    *len = n;
    return buf;
}

/* An 8-bit sRGB grey image of w x h pixels, through PNG and the loader (NULL, and a failed
 * check, when it does not load). */
static csf_image *grey_image(const unsigned char *px, int w, int h)
{
    size_t len = 0;
    unsigned char *png = encode(px, w, h, PNG_FORMAT_GRAY, &len);
    csf_image *img = NULL;
    csf_error e;
    CHECK_MSG(png && csf_image_load_png_memory(png, len, &img, &e) == CSF_OK, "grey image: %s", png ? e.msg : "encode");
    free(png);
    return img;
}

int main(void)
{
    csf_error e;
    csf_image *img = NULL;
    /* grey gradient: sRGB-encoded values decode to linear luminance */
    unsigned char grey[64 * 32];
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 64; x++) grey[y * 64 + x] = (unsigned char)(x * 4);
    size_t len;
    unsigned char *png = encode(grey, 64, 32, PNG_FORMAT_GRAY, &len);
    CHECK(png != NULL);
    CHECK_INT_EQ(csf_image_load_png_memory(png, len, &img, &e), CSF_OK);
    if (img) {
        CHECK_INT_EQ(img->width, 64);
        CHECK_INT_EQ(img->height, 32);
        double maxerr = 0;
        for (int x = 0; x < 64; x++) maxerr = fmax(maxerr, fabs(img->lum[5 * 64 + x] - srgb_decode(x * 4 / 255.0)));
        CHECK_MSG(maxerr < 2e-3, "sRGB decode error %g", maxerr);
        CHECK_NEAR(img->alpha[0], 1.0, 1e-6);
        csf_image_free(img);
        img = NULL;
    }
    /* damaged files are refused, never crash */
    CHECK_INT_EQ(csf_image_load_png_memory(png, len / 2, &img, &e), CSF_E_FORMAT);
    CHECK(img == NULL);
    CHECK_INT_EQ(csf_image_load_png_memory("not a png at all", 16, &img, &e), CSF_E_FORMAT);
    CHECK_STR_CONTAINS(e.msg, "PNG");
    CHECK_INT_EQ(csf_image_load_png_memory(png, 4, &img, &e), CSF_E_FORMAT);
    CHECK_INT_EQ(csf_image_load_png("/nonexistent/x.png", &img, &e), CSF_E_IO);
    CHECK_STR_CONTAINS(e.msg, "/nonexistent/x.png");
    /* a header claiming 100000 x 100000 px is refused before allocation */
    unsigned char *big = malloc(len);
    memcpy(big, png, len);
    big[16] = 0, big[17] = 0x01, big[18] = 0x86, big[19] = 0xa0; /* width 100000 */
    CHECK_INT_EQ(csf_image_load_png_memory(big, len, &img, &e), CSF_E_FORMAT);
    free(big);
    free(png);

    /* colour: pure green is Rec.709 luminance 0.7152; alpha is kept */
    unsigned char rgba[4 * 4 * 4];
    for (int i = 0; i < 16; i++) {
        rgba[4 * i] = 0, rgba[4 * i + 1] = 255, rgba[4 * i + 2] = 0;
        rgba[4 * i + 3] = i < 8 ? 255 : 0;
    }
    png = encode(rgba, 4, 4, PNG_FORMAT_RGBA, &len);
    CHECK_INT_EQ(csf_image_load_png_memory(png, len, &img, &e), CSF_OK);
    if (img) {
        CHECK_NEAR(img->lum[0], 0.7152, 0.01);
        CHECK_NEAR(img->alpha[0], 1.0, 1e-6);
        CHECK_NEAR(img->alpha[15], 0.0, 1e-6);
        CHECK_STR_CONTAINS(img->colour_note, "colour reduced to luminance");
        csf_image_free(img);
        img = NULL;
    }
    free(png);

    /* image stimulus: left half black, right half white, contrast 0.5 around the mean */
    unsigned char half[32 * 16];
    for (int i = 0; i < 32 * 16; i++) half[i] = (i % 32) < 16 ? 0 : 255;
    png = encode(half, 32, 16, PNG_FORMAT_GRAY, &len);
    CHECK_INT_EQ(csf_image_load_png_memory(png, len, &img, &e), CSF_OK);
    free(png);
    csf_presenter_config cfg;
    csf_presenter_config_defaults(&cfg);
    cfg.render_width_px = 480;
    cfg.render_height_px = 270;
    csf_presenter *p = stim_test_open(&cfg);
    csf_stimulus s;
    memset(&s, 0, sizeof s);
    s.kind = CSF_STIM_IMAGE;
    s.image = img;
    s.radius_deg = 4; /* half width */
    s.contrast = 0.5;
    csf_frame_info fi;
    CHECK_MSG(csf_presenter_draw(p, &s, 0, &fi, &e) == CSF_OK, "%s", e.msg);
    int w, h;
    csf_presenter_render_size(p, &w, &h);
    uint16_t *lv = malloc(sizeof(uint16_t) * 3 * w * h);
    CHECK_INT_EQ(csf_presenter_readback_levels(p, lv, &e), CSF_OK);
    const csf_geometry *g = csf_presenter_geometry(p);
    double sum_l = 0, sum_r = 0;
    int n_l = 0, n_r = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double xm = ((x + 0.5) / w - 0.5) * g->width_mm, ym = (0.5 - (y + 0.5) / h) * g->height_mm, u, v;
            csf_geometry_local_uv(g, 0, 0, xm, ym, &u, &v);
            if (fabs(v) > 1.5) continue;
            double L = csf_presenter_level_lum(p, lv[3 * ((size_t)y * w + x)]);
            if (u > -3.5 && u < -0.5) sum_l += L, n_l++;
            if (u > 0.5 && u < 3.5) sum_r += L, n_r++;
        }
    double black, max;
    csf_presenter_lum_range(p, &black, &max);
    double mean = 0.5 * (black + max);
    CHECK(n_l > 50 && n_r > 50);
    CHECK_NEAR(sum_l / n_l, 0.5 * mean, 0.03 * mean);
    CHECK_NEAR(sum_r / n_r, 1.5 * mean, 0.03 * mean);
    s.image = NULL;
    CHECK_INT_EQ(csf_presenter_validate(p, &s, &e), CSF_E_INVALID_ARG);

    /* the range check uses the image's real pixel range, not mean (1 +- contrast): a low-key image
     * (sRGB 160..210, within about +-30 % of its mean) fits at contrast 1 ... */
    unsigned char narrow[16 * 16];
    for (int i = 0; i < 16 * 16; i++) narrow[i] = i % 2 ? 160 : 210;
    csf_image *img_narrow = grey_image(narrow, 16, 16);
    s.image = img_narrow;
    s.contrast = 1;
    CHECK_MSG(csf_presenter_validate(p, &s, &e) == CSF_OK, "contrast-1 low-key image refused: %s", e.msg);
    /* ... while one white pixel in 16 on black spans mean (1 + 15 contrast): at contrast 0.2 that
     * is 4x the mean, beyond the display's white, and the message names the limit */
    unsigned char sparse[16 * 16];
    for (int i = 0; i < 16 * 16; i++) sparse[i] = i % 16 ? 0 : 255;
    csf_image *img_sparse = grey_image(sparse, 16, 16);
    s.image = img_sparse;
    s.contrast = 0.2;
    CHECK_INT_EQ(csf_presenter_validate(p, &s, &e), CSF_E_INVALID_ARG);
    char lim[32];
    snprintf(lim, sizeof lim, "%.4g cd/m2", max);
    CHECK_STR_CONTAINS(e.msg, lim);
    CHECK_STR_CONTAINS(e.msg, "pixel range");
    /* at a contrast its brightest pixel can reach it is drawn */
    s.contrast = 0.05;
    CHECK_MSG(csf_presenter_validate(p, &s, &e) == CSF_OK, "%s", e.msg);
    s.image = NULL;
    csf_image_free(img_narrow);
    csf_image_free(img_sparse);

    /* text screen: dark glyphs in the middle band of the field */
    CHECK_MSG(csf_presenter_text_screen(p, "Press SPACE\nto start", &e) == CSF_OK, "%s", e.msg);
    CHECK_INT_EQ(csf_presenter_readback_levels(p, lv, &e), CSF_OK);
    int bg = lv[0], dark = 0, dark_outside = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            if (lv[3 * ((size_t)y * w + x)] < bg - 30) {
                dark++;
                if (y < h * 0.3 || y > h * 0.7) dark_outside++;
            }
    CHECK_MSG(dark > 100, "%d dark pixels", dark);
    CHECK_INT_EQ(dark_outside, 0);
    free(lv);
    csf_presenter_close(p);
    csf_image_free(img);
    return CHECK_RESULT();
}
