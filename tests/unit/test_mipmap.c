/* Unit tests of the mip levels pfx makes itself (render/mipmap.c): each
 * texel of the level below is the mean of the texels under it, weighted
 * by shared area and rounded half up, worked out here by hand for even
 * and odd sides, 8 and 16 bits. No GL context. */
#include "render/mipmap.h"

#include <stdint.h>
#include <stdlib.h>

#include "test.h"

/* An even side: the mean of 2 x 2, exactly. Texel (x, y) channel c of a
 * 4 x 2 level holds 10 x + 100 y + c, so the left texel below has
 * (0 + 10 + 100 + 110) / 4 + c = 55 + c and the right 75 + c; a mean of
 * .5 rounds up ((1 + 2 + 2 + 2) / 4 = 1.75 -> 2, (1 + 1 + 2 + 2) / 4 =
 * 1.5 -> 2). */
static void test_even_means(void) {
    uint8_t src[2][4][4];
    for (int y = 0; y < 2; y++)
        for (int x = 0; x < 4; x++)
            for (int c = 0; c < 4; c++)
                src[y][x][c] = (uint8_t)(10 * x + 100 * y + c);
    int w = 0, h = 0;
    uint8_t *dst = pfx_mipmap_halve(src, 4, 2, 8, &w, &h);
    CHECK(dst != NULL);
    if (!dst)
        return;
    CHECK(w == 2 && h == 1);
    for (int c = 0; c < 4; c++) {
        CHECK(dst[c] == 55 + c);
        CHECK(dst[4 + c] == 75 + c);
    }
    free(dst);

    const uint8_t halves[2][2][4] = {{{1, 1, 0, 0}, {1, 2, 0, 0}}, {{2, 2, 0, 0}, {2, 2, 0, 0}}};
    dst = pfx_mipmap_halve(halves, 2, 2, 8, &w, &h);
    CHECK(dst != NULL && w == 1 && h == 1);
    if (dst) {
        CHECK(dst[0] == 2); /* 1.5 rounds up */
        CHECK(dst[1] == 2); /* 1.75 */
        CHECK(dst[2] == 0 && dst[3] == 0);
        free(dst);
    }
}

/* Odd sides: a row of 5 makes 2 texels of 2.5 source texels each,
 * (a + b + c / 2) / 2.5 and (c / 2 + d + e) / 2.5; a row of 3 makes one,
 * the mean of all three; a side of 1 stays 1. Values 0, 50, 100, 150, 200:
 * (0 + 50 + 50) / 2.5 = 40 and (50 + 150 + 200) / 2.5 = 160. */
static void test_odd_sides(void) {
    uint8_t row[5][4];
    for (int x = 0; x < 5; x++)
        for (int c = 0; c < 4; c++)
            row[x][c] = (uint8_t)(50 * x);
    int w = 0, h = 0;
    uint8_t *dst = pfx_mipmap_halve(row, 5, 1, 8, &w, &h);
    CHECK(dst != NULL);
    if (dst) {
        CHECK(w == 2 && h == 1);
        CHECK(dst[0] == 40 && dst[4] == 160);
        free(dst);
    }
    /* A column of 3 (7, 8, 10): one texel of 25 / 3 = 8.33 -> 8. */
    const uint8_t column[3][4] = {{7, 7, 7, 7}, {8, 8, 8, 8}, {10, 10, 10, 10}};
    dst = pfx_mipmap_halve(column, 1, 3, 8, &w, &h);
    CHECK(dst != NULL);
    if (dst) {
        CHECK(w == 1 && h == 1 && dst[0] == 8 && dst[3] == 8);
        free(dst);
    }
}

/* 16 bits: the same rule on 0..65535, with no overflow at the top. */
static void test_sixteen_bits(void) {
    const uint16_t src[2][2][4] = {{{65535, 0, 1, 65535}, {65535, 0, 2, 65535}},
                                   {{65535, 1, 2, 65535}, {65534, 1, 2, 65535}}};
    int w = 0, h = 0;
    uint16_t *dst = pfx_mipmap_halve(src, 2, 2, 16, &w, &h);
    CHECK(dst != NULL);
    if (dst) {
        CHECK(w == 1 && h == 1);
        CHECK(dst[0] == 65535); /* 65534.75 */
        CHECK(dst[1] == 1);     /* 0.5 rounds up */
        CHECK(dst[2] == 2);     /* 1.75 */
        CHECK(dst[3] == 65535);
        free(dst);
    }
}

int main(void) {
    RUN(test_even_means);
    RUN(test_odd_sides);
    RUN(test_sixteen_bits);
    return TEST_EXIT();
}
