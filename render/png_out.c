#include "render/png_out.h"

#include <errno.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cellmap/output.h"

/* Everything libpng touches after setjmp lives in this struct, so nothing
 * is clobbered by longjmp. */
typedef struct png_job {
    FILE *file;
    png_structp png;
    png_infop info;
    uint8_t *row;
} png_job;

/* The pixels to write: RGBA (stored as RGB), or palette indices. */
typedef struct png_pixels {
    const uint8_t *data;
    int width, height;
    const uint8_t *palette; /* NULL: RGBA; else n_colours RGB triples */
    int n_colours;
    double dpi; /* > 0: written as pHYs */
} png_pixels;

static cm_status encode(png_job *job, const png_pixels *px, const cm_png_text *texts, int n_texts)
{
    if (setjmp(png_jmpbuf(job->png)))
        return CM_EIO;
    const int width = px->width, height = px->height;
    png_init_io(job->png, job->file);
    png_set_IHDR(job->png, job->info, (png_uint_32)width, (png_uint_32)height, 8,
                 px->palette ? PNG_COLOR_TYPE_PALETTE : PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    if (px->palette) {
        png_color colours[256];
        for (int k = 0; k < px->n_colours; k++)
            colours[k] =
                (png_color){px->palette[3 * k], px->palette[3 * k + 1], px->palette[3 * k + 2]};
        png_set_PLTE(job->png, job->info, colours, px->n_colours);
    }
    if (px->dpi > 0) {
        const png_uint_32 per_metre = (png_uint_32)(px->dpi / 0.0254 + 0.5);
        png_set_pHYs(job->png, job->info, per_metre, per_metre, PNG_RESOLUTION_METER);
    }
    /* Basins are flat areas of colour, which zlib's fastest level finds as
     * long matches without a filter. Measured on bench_render's figures
     * (issue 51): against the Sub filter with the RLE strategy at level 3,
     * 11-17 % less time (a 4096x4096 figure in 155 ms instead of 174, a
     * 1000x1000 one in 11.1 instead of 13.2) and files 23-37 % smaller;
     * level 2 is slower for 3 % smaller files, and the Up and Sub filters,
     * RLE or Huffman-only coding slower still. */
    png_set_compression_level(job->png, 1);
    png_set_filter(job->png, 0, PNG_FILTER_NONE);
    for (int i = 0; i < n_texts; i++) {
        png_text t;
        memset(&t, 0, sizeof t);
        t.compression = PNG_TEXT_COMPRESSION_NONE;
        t.key = (png_charp)texts[i].key;
        t.text = (png_charp)texts[i].value;
        png_set_text(job->png, job->info, &t, 1);
    }
    png_write_info(job->png, job->info);
    for (int y = 0; y < height; y++) {
        if (px->palette) {
            png_write_row(job->png, px->data + (size_t)y * (size_t)width);
            continue;
        }
        const uint8_t *src = px->data + (size_t)y * (size_t)width * 4;
        for (int x = 0; x < width; x++)
            memcpy(job->row + 3 * (size_t)x, src + 4 * (size_t)x, 3);
        png_write_row(job->png, job->row);
    }
    png_write_end(job->png, job->info);
    return CM_OK;
}

static cm_status write_file(const char *path, const png_pixels *px, const cm_png_text *texts,
                            int n_texts, char *msg, size_t msg_size)
{
    const int width = px->width;
    cm_output out;
    cm_status st = cm_output_begin(&out, path, false, msg, msg_size);
    if (st != CM_OK)
        return st;
    png_job job;
    memset(&job, 0, sizeof job);
    job.file = fopen(out.tmp, "wb");
    if (!job.file) {
        st = cm_fail(CM_EIO, msg, msg_size, "cannot create %s: %s (check the directory exists and "
                     "is writable)", out.tmp, strerror(errno));
        cm_output_abandon(&out);
        return st;
    }
    job.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    job.info = job.png ? png_create_info_struct(job.png) : NULL;
    job.row = malloc(3 * (size_t)width);
    errno = 0;
    st = job.png && job.info && job.row ? encode(&job, px, texts, n_texts) : CM_ENOMEM;
    const int error = errno; /* why libpng's write failed, if it did */
    png_destroy_write_struct(&job.png, &job.info);
    free(job.row);
    const cm_status closed = cm_output_close_stream(&out, job.file, msg, msg_size);
    if (st == CM_OK && closed == CM_OK)
        return cm_output_commit(&out, msg, msg_size);
    cm_output_abandon(&out);
    if (st == CM_OK)
        return closed; /* its message names the reason */
    return cm_fail(st, msg, msg_size, "cannot write PNG %s: %s", path,
                   st == CM_EIO && error ? strerror(error) : cm_strerror(st));
}

cm_status cm_png_write(const char *path, const uint8_t *rgba, int width, int height, double dpi,
                       const cm_png_text *texts, int n_texts, char *msg, size_t msg_size)
{
    const png_pixels px = {rgba, width, height, NULL, 0, dpi};
    return write_file(path, &px, texts, n_texts, msg, msg_size);
}

cm_status cm_png_write_indexed(const char *path, const uint8_t *index, int width, int height,
                               double dpi, const uint8_t *palette, int n_colours,
                               const cm_png_text *texts, int n_texts, char *msg, size_t msg_size)
{
    if (n_colours < 1 || n_colours > 256)
        return cm_fail(CM_EINVAL, msg, msg_size, "a PNG palette holds 1..256 colours, not %d",
                       n_colours);
    const png_pixels px = {index, width, height, palette, n_colours, dpi};
    return write_file(path, &px, texts, n_texts, msg, msg_size);
}

cm_status cm_png_encode(const uint8_t *rgba, int width, int height, uint8_t **out, size_t *size,
                        char *msg, size_t msg_size)
{
    const png_pixels px = {rgba, width, height, NULL, 0, 0};
    char *buf = NULL;
    png_job job;
    memset(&job, 0, sizeof job);
    job.file = open_memstream(&buf, size);
    job.png = job.file ? png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL) : NULL;
    job.info = job.png ? png_create_info_struct(job.png) : NULL;
    job.row = malloc(3 * (size_t)width);
    cm_status st = job.png && job.info && job.row ? encode(&job, &px, NULL, 0) : CM_ENOMEM;
    png_destroy_write_struct(&job.png, &job.info);
    free(job.row);
    if (job.file && fclose(job.file) != 0 && st == CM_OK)
        st = CM_ENOMEM;
    if (st != CM_OK) {
        free(buf);
        return cm_fail(st, msg, msg_size, "cannot encode a %dx%d PNG: %s", width, height,
                       cm_strerror(st));
    }
    *out = (uint8_t *)buf;
    return CM_OK;
}
