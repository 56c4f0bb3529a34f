/* The float image to bytes. A pixel holds premultiplied colour P = (r, g,
 * b) and coverage A. Exposure multiplies P by 2^EV; the tone curve maps
 * each of its channels (none: as it is, clipped at 1 below; reinhard:
 * x / (1 + x), and 1 for +inf; aces: Narkowicz's 2015 fit of the ACES filmic curve,
 * x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14)).
 *
 * preserve_hue k: a curve applied to each channel by itself turns any
 * bright colour towards white (orange at 8x: (8, 4, 0.8) -> (1, 0.98,
 * 0.8)), so a fire's additive core loses its hue. Mapping the brightest
 * channel m instead and scaling all three by curve(m) / m keeps their
 * ratios, so hue and saturation, exactly. With k > 0, each channel c (after
 * the gain, x_c) becomes y_c = q_c + k (h_c - q_c), with q_c = min(1,
 * curve(x_c)) and h_c = x_c (min(1, curve(m)) / m) (none's curve is x
 * itself); k between 0 and 1 lets highlights whiten part way. Where m is
 * not a positive finite number y_c = q_c. k = 0 is the per-channel curve
 * as it always was, to the bit. Then:
 *
 * straight alpha: additive particles add light with zero coverage, so P can
 * exceed A (on a transparent background A may even be 0 under a bright
 * glow). Dividing by A would blow up, and storing A alone would drop the
 * glow. So the output alpha is A' = min(1, max(A, r, g, b)) and the output
 * colour clamp(P / A', 0, 1) (all zero when A' = 0). Composited over black
 * the result is colour * A' = P whenever P <= 1: an additive particle on a
 * transparent background looks, placed over black, exactly as it rendered
 * over black, and where alpha blending dominates (A >= every channel) this
 * is the ordinary un-premultiply.
 *
 * premultiplied alpha: P and A as they are, clamped to [0, 1]: additive
 * light is colour with zero alpha, which composites correctly with
 * "one, one minus source alpha" (what engines call premultiplied blending).
 *
 * Bytes are lround(255 x). With dither, each channel of a pixel that is
 * not the background gets a fixed offset in [-0.5, 0.5) / 255 from a hash of
 * its position and channel first: smooth gradients then do not band, exact
 * 0 and 1 stay exact, and the flat background is never speckled.
 *
 * It is a pure function of the float image and the tone (render/image.h),
 * so the frame queue's encoder threads (output/frame_queue.c) run it, off
 * the drawing thread, and any thread gives the same bytes.
 *
 * The arithmetic is in float (IEEE single, no fused multiply-add), each
 * operation in the order written above; 2^EV is rounded to float once.
 * tests/unit/test_png.c restates all of this one pixel at a time, plainly,
 * and compares.
 *
 * Cost: most of a particle frame is untouched background, so eight
 * all-zero pixels (all 128 bytes zero; -0.0 takes the general path) are
 * written as zero at once; the rest are computed eight at a time, with no
 * libm calls. On frame 60 of effects/fire.yaml at 512x512 (80 %
 * transparent), ACES with dither: 2.5 ms a frame pixel by pixel in double,
 * 1.1 ms four at a time in double, 0.88 ms eight at a time in float; in a
 * whole render (perf) its share of the CPU fell from 6.1 % to 3.2 %. Float
 * changed 10 of 18.9 million bytes of that render, each by 1. preserve_hue
 * costs a second curve and a division a pixel: on a 512x512 frame with
 * every pixel covered, ACES with dither took 1.2 ms, with preserve_hue 1
 * 1.6 ms (a loop over pfx_float_image_to_rgba8, 100 frames, -O2). */
#include "render/image.h"
#include "render/render.h"

#include "base/clones.h"

#include <math.h>
#include <string.h>

typedef struct tone {
    float gain; /* 2^exposure */
    pfx_tonemap curve;
    float hue; /* preserve_hue */
    bool premultiplied, dither;
    bool plain; /* gain 1, no curve: the fast path */
    uint32_t clear_bits[4];
} tone;

static tone make_tone(const pfx_tone *in, const float clear[4]) {
    tone t = {.gain = (float)exp2(in->exposure),
              .curve = in->tonemap,
              .hue = (float)in->preserve_hue,
              .premultiplied = in->alpha == PFX_ALPHA_PREMULTIPLIED,
              .dither = in->dither};
    t.plain = t.gain == 1 && t.curve == PFX_TONEMAP_NONE && t.hue == 0;
    memcpy(t.clear_bits, clear, sizeof t.clear_bits);
    return t;
}

pfx_tone pfx_render_tone(const pfx_render_settings *s) {
    return (pfx_tone){.exposure = s->exposure,
                      .tonemap = s->tonemap,
                      .preserve_hue = s->preserve_hue,
                      .alpha = s->alpha,
                      .dither = s->dither};
}

/* ---- Eight pixels at once ----
 * In GCC's vector extensions (clang reads them too): eight pixels'
 * channels in the lanes of a vector of floats, each lane going through the
 * operations above in order, in float, the same bits as one pixel at a
 * time in float. What one pixel at a time would branch around (the curve
 * of a non-positive channel, a division by a zero alpha) is computed and
 * discarded by a select. */
/* The helpers below pass 32-byte vectors by value; they are always inlined
 * and never cross a call, so GCC's note that such an argument's ABI
 * differs with AVX (-Wpsabi) does not apply. */
#pragma GCC diagnostic ignored "-Wpsabi"
typedef float v8f __attribute__((vector_size(32)));
typedef int32_t v8i __attribute__((vector_size(32)));
typedef uint32_t v8u __attribute__((vector_size(32)));
typedef uint32_t v4u __attribute__((vector_size(16)));

/* Lane-wise m ? a : b, m a comparison's all-ones or zero lanes. */
static inline __attribute__((always_inline)) v8f select8(v8i m, v8f a, v8f b) {
    return (v8f)((m & (v8i)a) | (~m & (v8i)b));
}

static inline __attribute__((always_inline)) v8f splat8(float x) {
    return (v8f){x, x, x, x, x, x, x, x};
}

/* fmax without the libm call: the larger of x and y, the other one when
 * either is NaN. */
static inline __attribute__((always_inline)) v8f max_of8(v8f x, v8f y) {
    return select8((y > x) | (x != x), y, x);
}

/* The tone curve of x, already multiplied by the gain. */
static inline __attribute__((always_inline)) v8f curve8(const tone *t, v8f x) {
    if (t->curve == PFX_TONEMAP_REINHARD) {
        const v8f y = select8(x < INFINITY, x / (1 + x), splat8(1));
        return select8(x > 0, y, splat8(0));
    }
    if (t->curve == PFX_TONEMAP_ACES) {
        v8f y = x * (2.51f * x + 0.03f) / (x * (2.43f * x + 0.59f) + 0.14f);
        y = select8(y < 1, y, splat8(1));
        return select8(x > 0, y, splat8(0));
    }
    return x;
}

/* preserve_hue (the comment at the top): mixes the per-channel curve q of
 * the gained channels x towards x scaled by curve(m) / m, m their largest. */
static inline __attribute__((always_inline)) void keep_hue8(const tone *t, const v8f x[3],
                                                            v8f q[3]) {
    const v8f m = max_of8(max_of8(x[0], x[1]), x[2]);
    v8f cm = curve8(t, m);
    cm = select8(cm < 1, cm, splat8(1));
    const v8f s = cm / select8(m > 0, m, splat8(1));
    const v8i ok = (m > 0) & (m < INFINITY);
    for (int c = 0; c < 3; c++) {
        const v8f qc = select8(q[c] < 1, q[c], splat8(1));
        q[c] = select8(ok, qc + splat8(t->hue) * (x[c] * s - qc), q[c]);
    }
}

/* lround(255 x) clamped to a byte, lane-wise, as floats holding whole
 * numbers: for 0 < x < 1, y = 255 x lies in (0, 255), so truncation is
 * floor and y - floor(y) is exact, and rounding half away from zero is one
 * comparison. y is clamped before its conversion, so no lane converts out
 * of range; NaN gives 0. */
static inline __attribute__((always_inline)) v8f to_bytes8(v8f x) {
    const v8i positive = x > 0;
    const v8f y = select8(positive & (x < 1), 255.0f * x, splat8(0));
    const v8f t = __builtin_convertvector(__builtin_convertvector(y, v8i), v8f);
    const v8f r = t + select8(y - t >= 0.5f, splat8(1), splat8(0));
    return select8(positive, select8(x >= 1, splat8(255), r), splat8(0));
}

/* The dither offsets in [-0.5, 0.5) / 255 of the eight pixels from column
 * x of row y, channel c: a hash of the position and channel. */
static inline __attribute__((always_inline)) v8f dither8(int x, int y, int c) {
    v8u h = ((v8u){0, 1, 2, 3, 4, 5, 6, 7} + (uint32_t)x) * 0x8da6b343u;
    h ^= (uint32_t)y * 0xd8163841u ^ (uint32_t)c * 0xcb1ab31fu;
    h ^= h >> 15;
    h *= 0x2c1b3c6du;
    h ^= h >> 12;
    h *= 0x297a2d39u;
    h ^= h >> 15;
    const v8f u = __builtin_convertvector((v8i)(h >> 8), v8f);
    return (u / 16777216.0f - 0.5f) / 255.0f;
}

/* The 4 x 4 transpose of four pixels' words into four channels' (and
 * back: it is its own inverse). */
static inline __attribute__((always_inline)) void transpose4(const v4u in[4], v4u out[4]) {
    const v4u t0 = __builtin_shufflevector(in[0], in[1], 0, 4, 1, 5);
    const v4u t1 = __builtin_shufflevector(in[2], in[3], 0, 4, 1, 5);
    const v4u t2 = __builtin_shufflevector(in[0], in[1], 2, 6, 3, 7);
    const v4u t3 = __builtin_shufflevector(in[2], in[3], 2, 6, 3, 7);
    out[0] = __builtin_shufflevector(t0, t1, 0, 1, 4, 5);
    out[1] = __builtin_shufflevector(t0, t1, 2, 3, 6, 7);
    out[2] = __builtin_shufflevector(t2, t3, 0, 1, 4, 5);
    out[3] = __builtin_shufflevector(t2, t3, 2, 3, 6, 7);
}

/* Eight pixels (32 floats) at column x of row y into 32 bytes at dst. */
static inline __attribute__((always_inline)) void convert8(const tone *t, const float *src, int x,
                                                           int y, uint8_t *dst) {
    v4u px[8], lo[4], hi[4];
    v8u ch[4];
    memcpy(px, src, sizeof px);
    transpose4(px, lo);
    transpose4(px + 4, hi);
    for (int c = 0; c < 4; c++)
        ch[c] = __builtin_shufflevector(lo[c], hi[c], 0, 1, 2, 3, 4, 5, 6, 7);
    const v8u any = ch[0] | ch[1] | ch[2] | ch[3];
    const v8u differs = (ch[0] ^ t->clear_bits[0]) | (ch[1] ^ t->clear_bits[1]) |
                        (ch[2] ^ t->clear_bits[2]) | (ch[3] ^ t->clear_bits[3]);
    v8i zero = (v8i)(any == 0);
    const v8i dither = (v8i)(differs != 0) & -(int32_t)t->dither;
    v8f p[4];
    memcpy(p, ch, sizeof p);
    if (!t->plain) {
        v8f x[3];
        for (int c = 0; c < 3; c++) {
            x[c] = p[c] * splat8(t->gain);
            p[c] = curve8(t, x[c]);
        }
        if (t->hue > 0)
            keep_hue8(t, x, p);
    }
    if (!t->premultiplied) {
        v8f ap = max_of8(max_of8(p[3], p[0]), max_of8(p[1], p[2]));
        ap = select8(ap > 1, splat8(1), ap);
        zero |= ~(ap > 0);
        for (int c = 0; c < 3; c++)
            p[c] = p[c] / ap;
        p[3] = ap;
    }
    v8u word = {0};
    for (int c = 0; c < 4; c++) {
        const v8f v = select8(dither, p[c] + dither8(x, y, c), p[c]);
        const v8f b = select8(zero, splat8(0), to_bytes8(v));
        /* byte c of each pixel's word in memory is channel c */
        const int shift = __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__ ? 8 * c : 24 - 8 * c;
        word |= (v8u) __builtin_convertvector(b, v8i) << shift;
    }
    memcpy(dst, &word, sizeof word);
}

/* Eight pixels at column x of row y from src into dst, or zero when all
 * 128 bytes are. */
static inline __attribute__((always_inline)) void convert_octet(const tone *t, const float *src,
                                                                int x, int y, uint8_t *dst) {
    v8u bits[4];
    memcpy(bits, src, sizeof bits);
    const v8u any8 = bits[0] | bits[1] | bits[2] | bits[3];
    const v4u any = __builtin_shufflevector(any8, any8, 0, 1, 2, 3) |
                    __builtin_shufflevector(any8, any8, 4, 5, 6, 7);
    if (any[0] | any[1] | any[2] | any[3])
        convert8(t, src, x, y, dst);
    else
        memset(dst, 0, 32);
}

/* Pixels [from, to) of row y (top first) from src, the box's row, eight at
 * a time, the last ones padded with zeros; eight all-zero pixels, most of
 * a particle frame's box, are written as zero at once. PFX_CLONES: an AVX2
 * copy beside the baseline one, the same bytes. */
PFX_CLONES
static void convert_row(const tone *t, const float *src, size_t from, size_t to, int y,
                        uint8_t *dst) {
    size_t x = from;
    for (; to - x >= 8; x += 8, src += 32)
        convert_octet(t, src, (int)x, y, dst + 4 * x);
    if (x < to) {
        const size_t n = to - x;
        float octet[32] = {0};
        uint8_t out[32];
        memcpy(octet, src, n * 4 * sizeof *src);
        convert_octet(t, octet, (int)x, y, out);
        memcpy(dst + 4 * x, out, 4 * n);
    }
}

/* Row by row from the top: the part of the row inside the box run by run,
 * the rest as the background's bytes, computed once. */
void pfx_float_image_to_rgba8(const pfx_float_image *img, const pfx_tone *in, uint8_t *rgba) {
    const tone t = make_tone(in, img->clear);
    const size_t w = (size_t)img->width, bw = (size_t)(img->x1 - img->x0);
    const bool empty = img->x1 <= img->x0 || img->y1 <= img->y0;
    /* The background's bytes: eight pixels of it (never dithered: a pixel
     * equal to the background is not). */
    float clear8[32];
    uint8_t bg[32];
    for (int k = 0; k < 8; k++)
        memcpy(clear8 + 4 * k, img->clear, sizeof img->clear);
    convert8(&t, clear8, 0, 0, bg);
    uint32_t bg_word;
    memcpy(&bg_word, bg, 4);
    for (int y = 0; y < img->height; y++) {
        uint8_t *dst = rgba + (size_t)y * w * 4;
        int gl_y = img->height - 1 - y;
        bool in_box = !empty && gl_y >= img->y0 && gl_y < img->y1;
        size_t from = in_box ? (size_t)img->x0 : w, to = in_box ? (size_t)img->x1 : w;
        for (size_t x = 0; x < from; x++)
            memcpy(dst + 4 * x, &bg_word, 4);
        if (in_box)
            convert_row(&t, img->pixels + (size_t)(gl_y - img->y0) * bw * 4, from, to, y, dst);
        for (size_t x = to; x < w; x++)
            memcpy(dst + 4 * x, &bg_word, 4);
    }
}
