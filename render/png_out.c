#include "render/png_out.h"

#include <errno.h>
#include <png.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <zlib.h>

#include "cellmap/output.h"

typedef struct segment segment;

/* Everything libpng touches after setjmp lives in this struct, so nothing
 * is clobbered by longjmp. */
typedef struct png_job {
    FILE *file;
    png_structp png;
    png_infop info;
    segment *segs; /* the image data's deflated segments */
    int nsegs;
} png_job;

/* The pixels to write: RGBA (stored as RGB), or palette indices. */
typedef struct png_pixels {
    const uint8_t *data;
    int width, height;
    const uint8_t *palette; /* NULL: RGBA; else n_colours RGB triples */
    int n_colours;
    double dpi; /* > 0: written as pHYs */
} png_pixels;

/* ---- the image data, deflated in segments on every core ------------------------

   A PNG's image data is one zlib stream. Like pigz, we cut the scanlines
   into segments of about SEGMENT_BYTES, deflate each on its own (raw
   deflate, primed with the 32 KiB before it, so that matches across the cut
   are still found), end every segment but the last on a byte boundary
   (Z_SYNC_FLUSH: an empty stored block), and join them: the zlib header,
   the segments in order, and the Adler-32 of the whole, combined from the
   segments' (zlib's adler32_combine). Any inflater reads the result as one
   stream. Segments depend only on the image's size, so any number of
   threads writes the same bytes. libpng still writes every chunk; the
   segments go out as IDAT chunks through its chunk API. */

/* Basins are flat areas of colour, which zlib's fastest level finds as long
 * matches without a filter (the scanlines' filter byte is None). Measured on
 * bench_render's figures (issue 51): against the Sub filter with the RLE
 * strategy at level 3, 11-17 % less time and files 23-37 % smaller; level 2
 * is slower for 3 % smaller files, and the Up and Sub filters, RLE or
 * Huffman-only coding slower still. */
enum { SEGMENT_BYTES = 256 * 1024, WINDOW = 32768, LEVEL = 1 };

typedef struct segment {
    uint8_t *out; /* deflated bytes (raw deflate) */
    size_t size;
    uLong adler;  /* of the segment's scanlines */
    size_t raw;   /* their length */
} segment;

/* What the image's scanlines are made of: filter byte 0 (None), then RGB
 * from RGBA or the palette indices. */
static size_t scanline_bytes(const png_pixels *px)
{
    return 1 + (size_t)px->width * (px->palette ? 1 : 3);
}

static void scanline(const png_pixels *px, int y, uint8_t *to)
{
    const size_t w = (size_t)px->width;
    to[0] = PNG_FILTER_VALUE_NONE;
    if (px->palette) {
        memcpy(to + 1, px->data + (size_t)y * w, w);
        return;
    }
    const uint8_t *src = px->data + (size_t)y * w * 4;
    for (size_t x = 0; x < w; x++)
        memcpy(to + 1 + 3 * x, src + 4 * x, 3);
}

/* Deflates rows [y0, y1) as segment s (last: ends the deflate stream),
 * with z reset and primed with up to WINDOW bytes of the rows before y0;
 * scratch holds those rows and the segment's. False: out of memory. */
static bool deflate_segment(const png_pixels *px, int y0, int y1, int prime_rows, bool last,
                            z_stream *z, uint8_t *scratch, segment *s)
{
    const size_t line = scanline_bytes(px);
    const int p0 = y0 - prime_rows > 0 ? y0 - prime_rows : 0;
    for (int y = p0; y < y1; y++)
        scanline(px, y, scratch + (size_t)(y - p0) * line);
    const size_t primed = (size_t)(y0 - p0) * line, dict = primed < WINDOW ? primed : WINDOW;
    uint8_t *rows = scratch + primed;
    s->raw = (size_t)(y1 - y0) * line;
    s->adler = adler32(1, rows, (uInt)s->raw);
    if (deflateReset(z) != Z_OK || (dict && deflateSetDictionary(z, rows - dict, (uInt)dict) != Z_OK))
        return false;
    const size_t room = deflateBound(z, (uLong)s->raw) + 16; /* + the flush's empty block */
    s->out = malloc(room);
    if (!s->out)
        return false;
    z->next_in = rows;
    z->avail_in = (uInt)s->raw;
    z->next_out = s->out;
    z->avail_out = (uInt)room;
    const int rc = deflate(z, last ? Z_FINISH : Z_SYNC_FLUSH);
    s->size = room - z->avail_out;
    return last ? rc == Z_STREAM_END : rc == Z_OK && z->avail_in == 0 && z->avail_out > 0;
}

/* Every segment of the image, deflated on the OpenMP threads; false: out of
 * memory (what was made is freed by the caller). */
static bool deflate_image(const png_pixels *px, int seg_rows, segment *segs, int nsegs)
{
    const size_t line = scanline_bytes(px);
    const int prime_rows = (int)((WINDOW + line - 1) / line);
    bool ok = true;
#pragma omp parallel reduction(&& : ok)
    {
        z_stream z;
        memset(&z, 0, sizeof z);
        uint8_t *scratch = malloc((size_t)(seg_rows + prime_rows) * line);
        ok = scratch && deflateInit2(&z, LEVEL, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY) == Z_OK;
#pragma omp for schedule(dynamic, 1)
        for (int k = 0; k < nsegs; k++) {
            const int y0 = k * seg_rows, y1 = y0 + seg_rows < px->height ? y0 + seg_rows
                                                                          : px->height;
            if (ok)
                ok = deflate_segment(px, y0, y1, prime_rows, k == nsegs - 1, &z, scratch,
                                     &segs[k]);
        }
        deflateEnd(&z);
        free(scratch);
    }
    return ok;
}

/* The zlib stream's header: deflate with a 32 KiB window, the fastest
 * level, no dictionary (RFC 1950; a multiple of 31). */
static const uint8_t zlib_header[2] = {0x78, 0x01};

static void write_idat(png_structp png, const segment *segs, int nsegs)
{
    uLong adler = 1;
    for (int k = 0; k < nsegs; k++) {
        adler = adler32_combine(adler, segs[k].adler, (z_off_t)segs[k].raw);
        const bool first = k == 0, last = k == nsegs - 1;
        const size_t size = segs[k].size + (first ? 2 : 0) + (last ? 4 : 0);
        png_write_chunk_start(png, (png_const_bytep) "IDAT", (png_uint_32)size);
        if (first)
            png_write_chunk_data(png, zlib_header, 2);
        png_write_chunk_data(png, segs[k].out, segs[k].size);
        if (last) {
            const uint8_t tail[4] = {(uint8_t)(adler >> 24), (uint8_t)(adler >> 16),
                                     (uint8_t)(adler >> 8), (uint8_t)adler};
            png_write_chunk_data(png, tail, 4);
        }
        png_write_chunk_end(png);
    }
}

/* ---- the file --------------------------------------------------------------- */

static void describe(png_job *job, const png_pixels *px, const cm_png_text *texts, int n_texts)
{
    png_init_io(job->png, job->file);
    png_set_IHDR(job->png, job->info, (png_uint_32)px->width, (png_uint_32)px->height, 8,
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
    for (int i = 0; i < n_texts; i++) {
        png_text t;
        memset(&t, 0, sizeof t);
        t.compression = PNG_TEXT_COMPRESSION_NONE;
        t.key = (png_charp)texts[i].key;
        t.text = (png_charp)texts[i].value;
        png_set_text(job->png, job->info, &t, 1);
    }
}

/* The PNG: libpng's header chunks, the image data as deflated segments,
 * the end. */
static cm_status encode(png_job *job, const png_pixels *px, const cm_png_text *texts, int n_texts)
{
    const size_t line = scanline_bytes(px);
    const int seg_rows = line >= SEGMENT_BYTES ? 1 : (int)(SEGMENT_BYTES / line);
    const int nsegs = (px->height + seg_rows - 1) / seg_rows;
    job->segs = calloc((size_t)nsegs, sizeof *job->segs);
    job->nsegs = job->segs ? nsegs : 0;
    if (!job->segs || !deflate_image(px, seg_rows, job->segs, nsegs))
        return CM_ENOMEM;
    if (setjmp(png_jmpbuf(job->png)))
        return CM_EIO;
    describe(job, px, texts, n_texts);
    png_write_info(job->png, job->info);
    write_idat(job->png, job->segs, nsegs);
    png_write_chunk(job->png, (png_const_bytep) "IEND", NULL, 0);
    png_write_flush(job->png);
    return CM_OK;
}

static void job_free(png_job *job)
{
    png_destroy_write_struct(&job->png, &job->info);
    for (int k = 0; k < job->nsegs; k++)
        free(job->segs[k].out);
    free(job->segs);
}

static cm_status write_file(const char *path, const png_pixels *px, const cm_png_text *texts,
                            int n_texts, char *msg, size_t msg_size)
{
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
    errno = 0;
    st = job.png && job.info ? encode(&job, px, texts, n_texts) : CM_ENOMEM;
    const int error = errno; /* why libpng's write failed, if it did */
    job_free(&job);
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
    cm_status st = job.png && job.info ? encode(&job, &px, NULL, 0) : CM_ENOMEM;
    job_free(&job);
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
