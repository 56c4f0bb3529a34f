/* A texture's mip levels, made here rather than by glGenerateMipmap: the
 * GL specification leaves the filter and its rounding to each
 * implementation, so a GPU's levels and llvmpipe's could differ in the
 * last bits, and sprites read those levels by name (render/shader.c).
 * Made here, every renderer uploads the same texels. It does not choose
 * levels or sample them. */
#include "render/mipmap.h"

#include <math.h>
#include <stdlib.h>

/* The source texels under destination texel d of an axis shrunk from n
 * to m texels: [d n/m, (d + 1) n/m), at most 3 of them (n/m is at most 3,
 * as m = max(1, n/2)), and the length of each that lies inside. */
static int taps(int d, int n, int m, int *first, double weight[3]) {
    const double scale = (double)n / m, lo = d * scale, hi = (d + 1) * scale;
    int i = (int)floor(lo), k = 0;
    *first = i;
    for (; i < n && i < hi && k < 3; i++, k++)
        weight[k] = fmin(hi, i + 1.0) - fmax(lo, (double)i);
    return k;
}

/* One channel of texel (x, y): 8- or 16-bit. */
static double texel(const void *src, int w, int bits, int x, int y, int c) {
    const size_t at = ((size_t)y * (size_t)w + (size_t)x) * 4 + (size_t)c;
    return bits == 16 ? ((const uint16_t *)src)[at] : ((const uint8_t *)src)[at];
}

/* Box filtering by shared area: for even sides the mean of 2 x 2 texels,
 * (a + b + c + d) / 4 exactly in double, rounded half up; an odd side
 * spreads its texels over the wider cells (a 5-texel row makes two of
 * 2.5 each). Built with -ffp-contract=off, the same bits everywhere. */
void *pfx_mipmap_halve(const void *src, int w, int h, int bits, int *dw, int *dh) {
    const int mw = w > 1 ? w / 2 : 1, mh = h > 1 ? h / 2 : 1;
    const size_t bytes = (size_t)(bits / 8);
    void *dst = malloc((size_t)mw * (size_t)mh * 4 * bytes);
    if (!dst)
        return NULL;
    const double top = bits == 16 ? 65535.0 : 255.0, area = ((double)w / mw) * ((double)h / mh);
    for (int y = 0; y < mh; y++) {
        int y0;
        double wy[3];
        const int ny = taps(y, h, mh, &y0, wy);
        for (int x = 0; x < mw; x++) {
            int x0;
            double wx[3];
            const int nx = taps(x, w, mw, &x0, wx);
            for (int c = 0; c < 4; c++) {
                double sum = 0;
                for (int j = 0; j < ny; j++)
                    for (int i = 0; i < nx; i++)
                        sum += wx[i] * wy[j] * texel(src, w, bits, x0 + i, y0 + j, c);
                const double v = fmin(top, floor(sum / area + 0.5));
                const size_t at = ((size_t)y * (size_t)mw + (size_t)x) * 4 + (size_t)c;
                if (bits == 16)
                    ((uint16_t *)dst)[at] = (uint16_t)v;
                else
                    ((uint8_t *)dst)[at] = (uint8_t)v;
            }
        }
    }
    *dw = mw;
    *dh = mh;
    return dst;
}

GLenum pfx_texture_format(const pfx_image *img) {
    return img->bits == 16 ? GL_RGBA32F : GL_RGBA16F;
}

bool pfx_mipmap_upload(pfx_renderer *r, const pfx_image *img) {
    const bool wide = img->bits == 16;
    const void *level = img->pixels;
    void *made = NULL; /* the last level made, freed once the next is */
    int w = img->width, h = img->height;
    for (int k = 1; w > 1 || h > 1; k++) {
        void *next = pfx_mipmap_halve(level, w, h, img->bits, &w, &h);
        free(made);
        if (!next)
            return false;
        r->gl.TexImage2D(GL_TEXTURE_2D, k, pfx_texture_format(img), w, h, 0, GL_RGBA,
                         wide ? GL_UNSIGNED_SHORT : GL_UNSIGNED_BYTE, next);
        level = made = next;
    }
    free(made);
    return true;
}
