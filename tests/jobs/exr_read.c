/* An EXR reader for the tests, through OpenEXR's own Core library and
 * nothing of pfx: prints the header facts the tests assert (size, the
 * compression, each channel's name and type) and then every pixel as
 * floats, top row first, the channels in the order R G B A, as the
 * library decodes them.
 *
 *   exr_read FILE
 *
 * Output:
 *   size W H
 *   compression zip
 *   channel A half        (one line a channel, as the file lists them)
 *   pixels
 *   R G B A               (W x H lines, %.9g)
 * Exit 1 with a message on stderr when the file cannot be read. */
#include <openexr.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const compressions[] = {"none",  "rle", "zips", "zip",  "piz",
                                           "pxr24", "b44", "b44a", "dwaa", "dwab"};

static int fail(const char *path, const char *what, exr_result_t rv) {
    fprintf(stderr, "exr_read: '%s': %s: %s\n", path, what, exr_get_default_error_message(rv));
    return 1;
}

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: exr_read FILE\n");
        return 2;
    }
    const char *path = argv[1];
    exr_context_t ctx;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_result_t rv = exr_start_read(&ctx, path, &init);
    if (rv != EXR_ERR_SUCCESS)
        return fail(path, "cannot open", rv);
    exr_attr_box2i_t dw;
    exr_compression_t comp;
    const exr_attr_chlist_t *chans;
    int32_t lines;
    if ((rv = exr_get_data_window(ctx, 0, &dw)) || (rv = exr_get_compression(ctx, 0, &comp)) ||
        (rv = exr_get_channels(ctx, 0, &chans)) ||
        (rv = exr_get_scanlines_per_chunk(ctx, 0, &lines)))
        return fail(path, "cannot read the header", rv);
    const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
    printf("size %d %d\n", w, h);
    printf("compression %s\n", comp < EXR_COMPRESSION_LAST_TYPE ? compressions[comp] : "?");
    for (int c = 0; c < chans->num_channels; c++)
        printf("channel %s %s\n", chans->entries[c].name.str,
               chans->entries[c].pixel_type == EXR_PIXEL_HALF    ? "half"
               : chans->entries[c].pixel_type == EXR_PIXEL_FLOAT ? "float"
                                                                 : "uint");
    /* Every channel named R, G, B or A decoded to float into a plane of its
     * own. Not interleaved: OpenEXR 3.1.5's decoder mixes up the channels of
     * a four-channel half image decoded to interleaved floats (A comes back
     * as R), while the C++ RgbaInputFile and planar decoding agree. */
    float *px = calloc((size_t)w * (size_t)h * 4, sizeof *px);
    if (!px)
        return fail(path, "out of memory", EXR_ERR_OUT_OF_MEMORY);
    static const char order[] = "RGBA";
    exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
    for (int y = dw.min.y, first = 1; y <= dw.max.y; y += lines, first = 0) {
        exr_chunk_info_t chunk;
        if ((rv = exr_read_scanline_chunk_info(ctx, 0, y, &chunk)))
            return fail(path, "cannot read a chunk", rv);
        rv = first ? exr_decoding_initialize(ctx, 0, &chunk, &dec)
                   : exr_decoding_update(ctx, 0, &chunk, &dec);
        if (rv)
            return fail(path, "cannot decode", rv);
        for (int c = 0; c < dec.channel_count; c++) {
            exr_coding_channel_info_t *ch = &dec.channels[c];
            const char *at = strchr(order, ch->channel_name[0]);
            if (!at || ch->channel_name[1]) {
                ch->decode_to_ptr = NULL; /* skipped */
                continue;
            }
            ch->user_data_type = EXR_PIXEL_FLOAT;
            ch->user_bytes_per_element = 4;
            ch->user_pixel_stride = 4;
            ch->user_line_stride = w * 4;
            ch->decode_to_ptr = (uint8_t *)(px + (size_t)(at - order) * (size_t)w * (size_t)h +
                                            (size_t)(chunk.start_y - dw.min.y) * (size_t)w);
        }
        if (first && (rv = exr_decoding_choose_default_routines(ctx, 0, &dec)))
            return fail(path, "cannot decode", rv);
        if ((rv = exr_decoding_run(ctx, 0, &dec)))
            return fail(path, "cannot decode", rv);
    }
    exr_decoding_destroy(ctx, &dec);
    exr_finish(&ctx);
    puts("pixels");
    const size_t n = (size_t)w * (size_t)h;
    for (size_t i = 0; i < n; i++)
        printf("%.9g %.9g %.9g %.9g\n", px[i], px[n + i], px[2 * n + i], px[3 * n + i]);
    free(px);
    return 0;
}
