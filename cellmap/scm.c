#define _DEFAULT_SOURCE /* madvise */
#include "cellmap/scm.h"

#include "cellmap/classify.h"
#include "cellmap/grow.h"

#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#ifdef _OPENMP
#include <omp.h>
#endif

/* The per-cell arrays are a command's largest memory and are first touched
 * by the solve itself (or by the store paging a region in), so their page
 * faults are part of its time: on the virtual machines we measure on, first
 * touch of 12 bytes per cell in 4 KiB pages cost 2-27 ns/cell; on one where
 * it cost 17-27, in 2 MiB transparent huge pages it cost 0.9-3.5
 * (bench_scm's machine line). The array is asked for in huge pages, rounded
 * up to whole ones when that adds at most a quarter to its bytes: a 1000 x
 * 1000 view's 4 MB array, half in 4 KiB pages, took 4.6 ms to fill there,
 * and 0.3 ms in two huge pages (so does an array of 1.6 to 2 MiB, a 4x4
 * split's region of 500 000 cells). A smaller array keeps its tail in 4 KiB
 * pages, so that it takes no more memory than its bytes. */
void *cm_cells_array(size_t bytes)
{
    const size_t huge = (size_t)2 << 20;
    const size_t whole = (bytes + huge - 1) / huge * huge;
    const size_t asked = whole - bytes <= bytes / 4 ? whole : bytes;
    if (asked < huge)
        return malloc(bytes);
    void *p = NULL;
    if (posix_memalign(&p, huge, asked) != 0)
        return NULL;
#ifdef MADV_HUGEPAGE
    madvise(p, asked / huge * huge, MADV_HUGEPAGE); /* a hint: without it, 4 KiB pages */
#endif
    return p;
}

cm_status cm_region_alloc(cm_region *r, const cm_box *box, char *msg, size_t msg_size)
{
    memset(r, 0, sizeof *r);
    cm_status st = cm_box_check(box, msg, msg_size);
    if (st != CM_OK)
        return st;
    const uint64_t n = cm_box_cells(box);
    if (n > CM_REGION_MAX_CELLS)
        return cm_fail(CM_ETOOBIG, msg, msg_size,
                       "a region holds at most %llu cells (asked for %llu); split it",
                       (unsigned long long)CM_REGION_MAX_CELLS, (unsigned long long)n);
    r->box = *box;
    r->ncells = n;
    r->image = cm_cells_array(n * sizeof *r->image);
    r->group = cm_cells_array(n * sizeof *r->group);
    r->step = cm_cells_array(n * sizeof *r->step);
    if (!r->image || !r->group || !r->step) {
        cm_region_free(r);
        return cm_fail(CM_ENOMEM, msg, msg_size, "cannot allocate %llu cells (%llu bytes)",
                       (unsigned long long)n, (unsigned long long)(n * 12));
    }
    return CM_OK;
}

void cm_region_free(cm_region *r)
{
    if (!r)
        return;
    free(r->image);
    free(r->group);
    free(r->step);
    free(r->exit_target);
    memset(r, 0, sizeof *r);
}

uint64_t cm_region_bytes(const cm_region *r)
{
    return r->ncells * (sizeof *r->image + sizeof *r->group + sizeof *r->step) +
           r->nexits * (uint64_t)r->box.dim * sizeof *r->exit_target;
}

static bool same_cell(int dim, const int64_t *a, const int64_t *b)
{
    for (int d = 0; d < dim; d++)
        if (a[d] != b[d])
            return false;
    return true;
}

/* Image cell of the point x that starts in cell `from`, re-stepping while
 * the image stays in `from` (at most max_steps steps in all). Returns the
 * model's status; *in_world is false when there is no image cell. */
static int image_cell(const cm_model *model, const cm_lattice *lat, const int64_t *from,
                      int max_steps, double *x, int64_t *cell, bool *in_world)
{
    double y[CM_MAX_DIM];
    const int dim = lat->dim;
    for (int k = 1;; k++) {
        const int rc = model->step(model, x, y);
        *in_world = rc == 0 && cm_lattice_cell(lat, y, cell);
        if (rc < 0 || !*in_world || k >= max_steps || !same_cell(dim, cell, from))
            return rc < 0 ? rc : 0;
        for (int d = 0; d < dim; d++)
            x[d] = y[d];
    }
}

int cm_scm_image_cell(const cm_model *model, const cm_lattice *lat, const int64_t *from,
                      int max_steps, int64_t *cell, bool *in_world)
{
    double x[CM_MAX_DIM];
    cm_lattice_centre(lat, from, x);
    return image_cell(model, lat, from, max_steps, x, cell, in_world);
}

/* Exit targets one thread found, rows in the order it did them. */
typedef struct exit_buf {
    _Alignas(CM_CACHE_LINE) int64_t *cells; /* dim coordinates per exit (a line per thread) */
    uint64_t n, cap;
    int failed; /* out of memory */
} exit_buf;

/* Where the exits of each row were kept: thread and first entry. */
typedef struct row_exits {
    uint32_t *thread;
    uint64_t *first;
} row_exits;

static void keep_exit(exit_buf *eb, const int64_t *cell, int dim)
{
    if (eb->failed || cm_grow((void **)&eb->cells, &eb->cap, (eb->n + 1) * (uint64_t)dim,
                              sizeof *eb->cells) != CM_OK) {
        eb->failed = 1;
        return;
    }
    for (int d = 0; d < dim; d++) /* a loop: dim is small, a memcpy call is not */
        eb->cells[eb->n * (uint64_t)dim + (uint64_t)d] = cell[d];
    eb->n++;
}

/* The image a step gives: the sink (outside the world), the local index of
 * the cell it lands in, or an exit (outside the box). */
static uint32_t image_value(const cm_box *box, bool in_world, const int64_t *cell)
{
    if (!in_world)
        return CM_IMAGE_SINK;
    return cm_box_contains(box, cell) ? (uint32_t)cm_box_index(box, cell) : CM_IMAGE_EXIT;
}

/* The image of cell `from` of the box into *image, by single steps; with
 * eb, the target of an image that leaves the box is appended to it.
 * Returns the model's status. */
static int image_of_cell(const cm_model *model, const cm_lattice *lat, const cm_box *box,
                         int max_steps, const int64_t *from, exit_buf *eb, uint32_t *image)
{
    int64_t cell[CM_MAX_DIM];
    double x[CM_MAX_DIM];
    bool in_world;
    cm_lattice_centre(lat, from, x);
    const int rc = image_cell(model, lat, from, max_steps, x, cell, &in_world);
    if (rc < 0)
        return rc;
    *image = image_value(box, in_world, cell);
    if (*image == CM_IMAGE_EXIT && eb)
        keep_exit(eb, cell, box->dim);
    return 0;
}

/* Images of one row of the box: cells with local index row*nx .. row*nx+nx-1. */
static int images_of_row(const cm_model *model, const cm_lattice *lat, const cm_region *r,
                         int max_steps, uint64_t row, exit_buf *eb)
{
    const cm_box *box = &r->box;
    const uint64_t nx = (uint64_t)(box->hi[0] - box->lo[0]);
    int64_t from[CM_MAX_DIM];
    cm_box_cell(box, row * nx, from);
    for (uint64_t i = 0; i < nx; i++, from[0]++) {
        const int rc =
            image_of_cell(model, lat, box, max_steps, from, eb, &r->image[row * nx + i]);
        if (rc < 0)
            return rc;
    }
    return 0;
}

/* Cells a batch of images takes (models with step_n). */
#define BATCH 256

/* Whether coordinate d of the images (at) lies in the box (lo..hi) and
 * equals the cell's own (here, plus i along the row: step 1 in dimension
 * 0), and the local index so far (dimensions from the last down). */
CM_VECTOR_LOOP
static void place_coordinate(const double *restrict at, double lo, double hi, double here,
                             double step, int n, double *restrict in_box,
                             double *restrict stays, double *restrict local)
{
    const double side = hi - lo;
    for (int i = 0; i < n; i++) { /* an int: SSE2 converts no 64-bit integer to double */
        const double f = at[i];
        in_box[i] *= ((f >= lo) & (f < hi)) ? 1.0 : 0.0;
        stays[i] *= f == here + step * (double)i ? 1.0 : 0.0;
        local[i] = local[i] * side + (f - lo);
    }
}

/* A batch of images in arrays: the steps of cells first .. first + n - 1
 * of a row (step_n), where each lands as a lattice cell (floored doubles),
 * whether it is in the world, and, when inside the box, its local index
 * (exact in doubles: a box has fewer than 2^53 cells). */
typedef struct batch {
    double x[CM_MAX_DIM][BATCH], y[CM_MAX_DIM][BATCH], at[CM_MAX_DIM][BATCH];
    /* 1 or 0 (doubles, so that the loops vectorise): every coordinate in
     * the world, in the box, equal to the cell's own */
    double world[BATCH], in_box[BATCH], stays[BATCH];
    double local[BATCH];
    int rc[BATCH];
} batch;

/* Lattice coordinate d of the images, floored (vectorised: locals and
 * restrict keep the loop free of reloads). */
CM_VECTOR_LOOP
static void floor_coordinates(const double *restrict y, double origin, double width, size_t n,
                              double *restrict at, double *restrict world)
{
    const double limit = (double)CM_WORLD_LIMIT;
    for (size_t i = 0; i < n; i++) {
        const double u = (y[i] - origin) / width;
        const double inside = ((u >= -limit) & (u < limit)) ? 1.0 : 0.0; /* 0 for NaN */
        at[i] = cm_floor_exact(inside != 0.0 ? u : 0.0);
        world[i] *= inside;
    }
}

/* Fills b for the n cells of a row from cell `from` on. */
static void step_batch(const cm_model *model, const cm_lattice *lat, const cm_box *box,
                       const int64_t *from, size_t n, batch *b)
{
    const int dim = lat->dim;
    const double *xs[CM_MAX_DIM];
    double *ys[CM_MAX_DIM];
    double centre[CM_MAX_DIM];
    cm_lattice_centre(lat, from, centre);
    for (int d = 0; d < dim; d++) {
        xs[d] = b->x[d];
        ys[d] = b->y[d];
    }
    /* centres as cm_lattice_centre computes them: (double)cell is exact;
     * an int counter, which SSE2 converts to doubles in vectors (a size_t
     * kept this loop scalar) */
    const double first = (double)from[0];
    for (int i = 0; i < (int)n; i++)
        b->x[0][i] = lat->origin[0] + ((first + (double)i) + 0.5) * lat->width[0];
    for (int d = 1; d < dim; d++)
        for (size_t i = 0; i < n; i++)
            b->x[d][i] = centre[d];
    model->step_n(model, n, xs, ys, b->rc);
    for (size_t i = 0; i < n; i++) {
        b->world[i] = b->rc[i] == 0 ? 1.0 : 0.0;
        b->in_box[i] = 1.0;
        b->stays[i] = 1.0;
        b->local[i] = 0.0;
    }
    for (int d = 0; d < dim; d++)
        floor_coordinates(b->y[d], lat->origin[d], lat->width[d], n, b->at[d], b->world);
    for (int d = dim - 1; d >= 0; d--)
        place_coordinate(b->at[d], (double)box->lo[d], (double)box->hi[d], (double)from[d],
                         d == 0 ? 1.0 : 0.0, (int)n, b->in_box, b->stays, b->local);
}

/* The images the batch's first steps give (the sink, a local index or an
 * exit), and which cells need more: a model error, a re-step (the image is
 * the cell itself and restep is set), or an exit whose target is kept
 * (keep_exits). Vectorised, hence flags rather than branches, and a local
 * index converted as an int32 (it is below 2^31). */
CM_VECTOR_LOOP
static void first_images(const batch *restrict b, int n, int restep, int keep_exits,
                         uint32_t *restrict image, unsigned char *restrict special)
{
    for (int i = 0; i < n; i++) {
        const int world = b->world[i] != 0.0, in_box = b->in_box[i] != 0.0;
        const int32_t local = (int32_t)(in_box ? b->local[i] : 0.0);
        image[i] = !world ? CM_IMAGE_SINK : in_box ? (uint32_t)local : CM_IMAGE_EXIT;
        special[i] = (unsigned char)((b->rc[i] < 0) | (world & (b->stays[i] != 0.0) & restep) |
                                     (world & !in_box & keep_exits));
    }
}

/* The cells of a batch whose first image stays in them (with max_steps >
 * 1), stepped on from that image through step_n as image_cell steps them
 * one at a time: until the image leaves the cell, has none, or max_steps
 * steps are done. Their images go into image[]; an exit's target cell into
 * b->at, where the in-order pass keeps it as it keeps the others'; a
 * model's error into b->rc. b->x and b->y are reused: the batch's first
 * steps are done. */
static void restep_batch(const cm_model *model, const cm_lattice *lat, const cm_box *box,
                         int max_steps, const int64_t *from, size_t n, batch *b,
                         const unsigned char *special, uint32_t *image)
{
    const int dim = lat->dim;
    const double *xs[CM_MAX_DIM];
    double *ys[CM_MAX_DIM];
    int pos[BATCH], rc[BATCH];
    int64_t here[CM_MAX_DIM]; /* the cell being re-stepped */
    memcpy(here, from, sizeof here);
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        if (!special[i] || b->world[i] == 0.0 || b->stays[i] == 0.0)
            continue;
        for (int d = 0; d < dim; d++)
            b->x[d][m] = b->y[d][i];
        pos[m++] = (int)i;
    }
    for (int d = 0; d < dim; d++) {
        xs[d] = b->x[d];
        ys[d] = b->y[d];
    }
    for (int k = 2; m > 0; k++) { /* k: the step being done */
        model->step_n(model, m, xs, ys, rc);
        size_t going_on = 0;
        for (size_t j = 0; j < m; j++) {
            const int i = pos[j];
            if (rc[j] < 0) {
                b->rc[i] = rc[j];
                continue;
            }
            double y[CM_MAX_DIM];
            int64_t cell[CM_MAX_DIM];
            for (int d = 0; d < dim; d++)
                y[d] = b->y[d][j];
            const bool in_world = rc[j] == 0 && cm_lattice_cell(lat, y, cell);
            here[0] = from[0] + i;
            if (in_world && k < max_steps && same_cell(dim, cell, here)) {
                for (int d = 0; d < dim; d++)
                    b->x[d][going_on] = y[d];
                pos[going_on++] = i;
                continue;
            }
            image[i] = image_value(box, in_world, cell);
            if (image[i] == CM_IMAGE_EXIT) /* its target, for the in-order pass */
                for (int d = 0; d < dim; d++)
                    b->at[d][i] = (double)cell[d];
        }
        m = going_on;
    }
}

/* Images of one row with the model's step_n: as images_of_row gives them,
 * cell for cell (re-steps too, through restep_batch). */
static int images_of_row_batched(const cm_model *model, const cm_lattice *lat, const cm_region *r,
                                 int max_steps, uint64_t row, exit_buf *eb, batch *b)
{
    const cm_box *box = &r->box;
    const uint64_t nx = (uint64_t)(box->hi[0] - box->lo[0]);
    uint32_t *image = r->image + row * nx;
    int64_t from[CM_MAX_DIM], cell[CM_MAX_DIM];
    cm_box_cell(box, row * nx, from);
    for (uint64_t i0 = 0; i0 < nx; i0 += BATCH) {
        const size_t n = nx - i0 < BATCH ? (size_t)(nx - i0) : BATCH;
        step_batch(model, lat, box, from, n, b);
        unsigned char special[BATCH];
        first_images(b, (int)n, max_steps > 1, eb != NULL, image + i0, special);
        if (max_steps > 1)
            restep_batch(model, lat, box, max_steps, from, n, b, special, image + i0);
        for (size_t i = 0; i < n; i++) { /* in index order: exits are numbered so */
            if (!special[i])
                continue;
            if (b->rc[i] < 0)
                return b->rc[i];
            if (image[i0 + i] == CM_IMAGE_EXIT && eb) { /* its target kept */
                for (int d = 0; d < box->dim; d++)
                    cell[d] = (int64_t)b->at[d][i];
                keep_exit(eb, cell, box->dim);
            }
        }
        from[0] += (int64_t)n;
    }
    return 0;
}

/* Numbers the exits in local index order and moves their targets, kept by
 * the threads that found them, into the region's exit table: a lone
 * thread's list is that table already (it did the rows in order), and
 * becomes it without a copy (a region of a split solve, or a pan's strip,
 * has a thread of its own: 16 bytes of fresh memory an exit saved). */
static cm_status number_exits(cm_region *r, exit_buf *bufs, int threads, const row_exits *rows,
                              uint64_t nrows, char *msg, size_t msg_size)
{
    uint64_t nexits = 0;
    for (int t = 0; t < threads; t++) {
        if (bufs[t].failed)
            return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the exits");
        nexits += bufs[t].n;
    }
    if (nexits > CM_IMAGE_EXIT - CM_IMAGE_EXIT_BASE)
        return cm_fail(CM_ETOOBIG, msg, msg_size, "too many exits; split the region");
    const size_t dim = (size_t)r->box.dim;
    const bool adopt = threads == 1 && bufs[0].cells;
    /* an adopted list gives back the room it grew beyond its exits (in place) */
    r->exit_target = adopt ? realloc(bufs[0].cells, nexits * dim * sizeof *r->exit_target)
                           : malloc((nexits + 1) * dim * sizeof *r->exit_target);
    if (!r->exit_target)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %llu exits",
                       (unsigned long long)nexits);
    if (adopt)
        bufs[0].cells = NULL; /* the region's now */
    const uint64_t nx = r->ncells / nrows;
    uint64_t k = 0;
    for (uint64_t row = 0; row < nrows; row++) {
        /* indexed, not a pointer: a thread that found no exit has no array */
        const int64_t *from = bufs[rows->thread[row]].cells;
        uint64_t at = rows->first[row] * dim;
        for (uint64_t i = row * nx; i < (row + 1) * nx; i++) {
            if (r->image[i] != CM_IMAGE_EXIT)
                continue;
            for (size_t d = 0; d < dim && !adopt; d++)
                r->exit_target[k * dim + d] = from[at++];
            r->image[i] = CM_IMAGE_EXIT_BASE + (uint32_t)k++;
        }
    }
    r->nexits = nexits;
    r->exits_recorded = 1;
    return CM_OK;
}

/* The threads to use: `threads`, or the OpenMP default for 0 or less. */
static int threads_or_default(int threads)
{
#ifdef _OPENMP
    if (threads <= 0)
        threads = omp_get_max_threads();
#endif
    return threads > 0 ? threads : 1;
}

/* Regions below this many cells compute their images on one thread. */
#define PARALLEL_CELLS 1024

/* Cells of the rows a thread takes at a time. */
#define ROW_CHUNK_CELLS 4096

/* Rows between two calls of the progress callback (on the calling thread). */
#define PROGRESS_ROWS 64

/* The image loop: rows are independent and every image depends on its cell
 * alone, so the result is the same whatever the schedule or thread count. */
static cm_status images_of_rows(const cm_model *model, const cm_lattice *lat, int max_steps,
                                int threads, const cm_scm_options *opt, cm_region *r, char *msg,
                                size_t msg_size)
{
    const bool record_exits = opt && opt->record_exits;
    const cm_progress_fn progress = opt ? opt->progress : NULL;
    const uint64_t nx = (uint64_t)(r->box.hi[0] - r->box.lo[0]), nrows = r->ncells / nx;
    exit_buf *bufs = record_exits ? cm_thread_records((size_t)threads, sizeof *bufs) : NULL;
    row_exits rows = {NULL, NULL};
    if (record_exits) {
        rows.thread = malloc(nrows * sizeof *rows.thread);
        rows.first = malloc(nrows * sizeof *rows.first);
    }
    cm_status st = CM_OK;
    if (record_exits && (!bufs || !rows.thread || !rows.first))
        st = cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for the exits");
    atomic_int stop = 0; /* 1: the model aborted; 2: the progress callback cancelled */
    atomic_uint_fast64_t rows_done = 0; /* by every thread: what the calling thread reports */
    /* Rows are handed out a few thousand cells at a time, as threads ask:
     * rows cost more where cells re-step or leave, and a thread of a
     * shared machine may lose its core for a while; equal shares fixed in
     * advance left one thread waiting for the other. */
    const int chunk = nx >= ROW_CHUNK_CELLS ? 1 : (int)(ROW_CHUNK_CELLS / nx);
    if (st == CM_OK) {
    /* a few cells are quicker on one thread than waking others */
#pragma omp parallel num_threads(threads) if (r->ncells >= PARALLEL_CELLS)
    {
        int t = 0;
#ifdef _OPENMP
        t = omp_get_thread_num();
#endif
        exit_buf *eb = bufs ? &bufs[t] : NULL;
        batch *b = model->step_n ? malloc(sizeof *b) : NULL; /* NULL: the scalar path */
        uint64_t mine = 0; /* rows this thread did */
#pragma omp for schedule(dynamic, chunk)
        for (int64_t row = 0; row < (int64_t)nrows; row++) {
            if (eb) {
                rows.thread[row] = (uint32_t)t;
                rows.first[row] = eb->n;
            }
            if (atomic_load_explicit(&stop, memory_order_relaxed))
                continue;
            const int rc = b ? images_of_row_batched(model, lat, r, max_steps, (uint64_t)row,
                                                     eb, b)
                             : images_of_row(model, lat, r, max_steps, (uint64_t)row, eb);
            if (rc < 0)
                atomic_store(&stop, 1);
            const uint64_t done =
                progress ? atomic_fetch_add_explicit(&rows_done, 1, memory_order_relaxed) + 1 : 0;
            if (t == 0 && progress && ++mine % PROGRESS_ROWS == 0 &&
                progress(opt->user, "images", (double)done / (double)nrows) != 0)
                atomic_store(&stop, 2);
        }
        free(b);
    }
    }
    /* The images are done: said on the calling thread whatever share of
     * the rows it did (on a busy machine the other threads may have done
     * them all), and a last chance to cancel before classification. */
    if (st == CM_OK && stop == 0 && progress && progress(opt->user, "images", 1.0) != 0)
        stop = 2;
    if (st == CM_OK && stop == 1)
        st = cm_fail(CM_EMODEL, msg, msg_size, "model %s aborted the computation", model->name);
    if (st == CM_OK && stop == 2)
        st = cm_fail(CM_ECANCELED, msg, msg_size, "cancelled");
    if (st == CM_OK && record_exits)
        st = number_exits(r, bufs, threads, &rows, nrows, msg, msg_size);
    for (int t = 0; bufs && t < threads; t++)
        free(bufs[t].cells);
    free(bufs);
    free(rows.thread);
    free(rows.first);
    return st;
}

cm_status cm_scm_images(const cm_model *model, const cm_lattice *lat, const cm_scm_options *opt,
                        cm_region *r, char *msg, size_t msg_size)
{
    if (!model || !model->step || model->dim != lat->dim || r->box.dim != lat->dim)
        return cm_fail(CM_EINVAL, msg, msg_size, "model, lattice and region dimensions differ");
    const cm_status within = cm_model_check_box(model, lat, &r->box, msg, msg_size);
    if (within != CM_OK) /* a cell beyond an angle's period would never be an image */
        return within;
    const int max_steps = opt && opt->max_steps > 1 ? opt->max_steps : 1;
    const int threads = threads_or_default(opt ? opt->threads : 0);
    free(r->exit_target);
    r->exit_target = NULL;
    r->nexits = 0;
    r->exits_recorded = 0;
    return images_of_rows(model, lat, max_steps, threads, opt, r, msg, msg_size);
}

/* Regions below this many cells are classified, and summarised, on one
 * thread. */
#define PARALLEL_CLASSIFY_CELLS 65536

void cm_scm_slow_share(const cm_region *r, int threads, double share[CM_MAX_DIM])
{
    /* Called on every solve's summary, so no cm_box_cell per cell: each
     * thread counts its cells' positions up from the first of its share,
     * and finds an image's with one 32-bit division per dimension but the
     * last (local indices stay below 2^32). The counts are integers: the
     * same whatever the thread count. */
    const int dim = r->box.dim;
    uint32_t side[CM_MAX_DIM];
    for (int d = 0; d < dim; d++)
        side[d] = (uint32_t)(r->box.hi[d] - r->box.lo[d]);
    uint64_t moved = 0, same[CM_MAX_DIM] = {0};
#pragma omp parallel num_threads(threads_or_default(threads)) \
    if (r->ncells >= PARALLEL_CLASSIFY_CELLS) \
    reduction(+ : moved, same[:CM_MAX_DIM])
    {
        int t = 0, team = 1;
#ifdef _OPENMP
        t = omp_get_thread_num();
        team = omp_get_num_threads();
#endif
        const uint64_t lo = r->ncells * (uint64_t)t / (uint64_t)team,
                       hi = r->ncells * (uint64_t)(t + 1) / (uint64_t)team;
        int64_t first[CM_MAX_DIM];
        uint32_t at[CM_MAX_DIM] = {0}, to[CM_MAX_DIM];
        cm_box_cell(&r->box, lo, first);
        for (int d = 0; d < dim; d++)
            at[d] = (uint32_t)(first[d] - r->box.lo[d]);
        for (uint64_t i = lo; i < hi; i++) {
            const uint32_t j = r->image[i];
            if (j < r->ncells && j != i) { /* not the sink, an exit or a fixed cell */
                uint32_t rest = j;
                for (int d = 0; d < dim - 1; d++) {
                    to[d] = rest % side[d];
                    rest /= side[d];
                }
                to[dim - 1] = rest;
                moved++;
                for (int d = 0; d < dim; d++)
                    same[d] += at[d] == to[d];
            }
            for (int d = 0; d < dim && ++at[d] == side[d]; d++)
                at[d] = 0;
        }
    }
    for (int d = 0; d < CM_MAX_DIM; d++)
        share[d] = d < dim && moved ? (double)same[d] / (double)moved : NAN;
}

cm_status cm_scm_classify(cm_region *r, int threads, char *msg, size_t msg_size)
{
    threads = r->ncells < PARALLEL_CLASSIFY_CELLS ? 1 : threads_or_default(threads);
    return cm_classify_threads((uint32_t)r->ncells, r->image, r->group, r->step, &r->ngroups,
                               r->exits_recorded, threads, msg, msg_size);
}

cm_status cm_scm_solve(const cm_model *model, const cm_lattice *lat, const cm_scm_options *opt,
                       cm_region *r, char *msg, size_t msg_size)
{
    cm_status st = cm_scm_images(model, lat, opt, r, msg, msg_size);
    /* classification is one pass that cannot stop half-way: a cancel
     * between the two phases is the last one honoured */
    if (st == CM_OK && opt && opt->progress && opt->progress(opt->user, "classification", 0) != 0)
        st = cm_fail(CM_ECANCELED, msg, msg_size, "cancelled");
    if (st == CM_OK)
        st = cm_scm_classify(r, opt ? opt->threads : 0, msg, msg_size);
    return st;
}

bool cm_cell_less(const int64_t *a, const int64_t *b, int dim)
{
    for (int d = dim - 1; d >= 0; d--)
        if (a[d] != b[d])
            return a[d] < b[d];
    return false;
}

uint64_t cm_cell_search(const int64_t *cells, uint64_t n, int dim, const int64_t *cell)
{
    uint64_t lo = 0, hi = n;
    while (lo < hi) { /* the first cell not before `cell` */
        const uint64_t mid = lo + (hi - lo) / 2;
        if (cm_cell_less(cells + mid * (uint64_t)dim, cell, dim))
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < n && !cm_cell_less(cell, cells + lo * (uint64_t)dim, dim) ? lo : UINT64_MAX;
}

void cm_group_add_periodic(cm_group_info *gi, const cm_lattice *lat, const int64_t *cell)
{
    double x[CM_MAX_DIM];
    cm_lattice_centre(lat, cell, x);
    if (gi->period == 0 || cm_cell_less(cell, gi->anchor, lat->dim))
        memcpy(gi->anchor, cell, (size_t)lat->dim * sizeof *cell);
    for (int d = 0; d < lat->dim; d++) {
        if (gi->period == 0 || x[d] < gi->lo[d])
            gi->lo[d] = x[d];
        if (gi->period == 0 || x[d] > gi->hi[d])
            gi->hi[d] = x[d];
        gi->centre[d] += x[d];
    }
    gi->period++;
}

void cm_group_finish(cm_group_info *gi, int dim)
{
    for (int d = 0; d < dim && gi->period > 0; d++)
        gi->centre[d] /= gi->period;
}

cm_status cm_scm_groups(const cm_region *r, const cm_lattice *lat, cm_group_info *groups,
                        uint64_t *sink_cells)
{
    uint64_t sink = 0;
    for (uint32_t k = 0; k < r->ngroups; k++) {
        memset(&groups[k], 0, sizeof groups[k]);
        groups[k].id = k + 1;
    }
    for (uint64_t i = 0; i < r->ncells; i++) {
        const uint32_t g = r->group[i];
        if (g == CM_GROUP_NONE)
            continue;
        if (g == 0 || cm_is_node_ref(g)) {
            sink++;
            continue;
        }
        cm_group_info *gi = &groups[g - 1];
        gi->basin_cells++;
        if (r->step[i] != 0)
            continue;
        int64_t cell[CM_MAX_DIM];
        cm_box_cell(&r->box, i, cell);
        cm_group_add_periodic(gi, lat, cell);
    }
    for (uint32_t k = 0; k < r->ngroups; k++)
        cm_group_finish(&groups[k], lat->dim);
    if (sink_cells)
        *sink_cells = sink;
    return CM_OK;
}

const char *cm_group_kind_name(int kind)
{
    return kind == CM_GROUP_STICKING ? "sticking" : "attractor";
}

bool cm_cell_at_rest(const cm_model *model, const cm_lattice *lat, const int64_t *cell)
{
    double x[CM_MAX_DIM], y[CM_MAX_DIM];
    if (!model->at_rest)
        return false;
    cm_lattice_centre(lat, cell, x);
    return model->step(model, x, y) == CM_STEP_OK && model->at_rest(model, y);
}

cm_status cm_scm_label_groups(const cm_model *model, const cm_lattice *lat, const cm_region *r,
                              cm_group_info *groups, uint32_t n, char *msg, size_t msg_size)
{
    /* per group: 1 while every periodic cell seen is at rest, 2 once one moves */
    uint8_t *rest = calloc((size_t)n + 1, 1);
    if (!rest)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory labelling %u groups", n);
    for (uint64_t i = 0; model->at_rest && i < r->ncells; i++) {
        const uint32_t g = r->group[i];
        if (g == CM_GROUP_NONE || g == 0 || g > n || r->step[i] != 0 || rest[g] == 2)
            continue;
        int64_t cell[CM_MAX_DIM];
        cm_box_cell(&r->box, i, cell);
        rest[g] = cm_cell_at_rest(model, lat, cell) ? 1 : 2;
    }
    for (uint32_t k = 0; k < n; k++)
        groups[k].kind = rest[k + 1] == 1 ? CM_GROUP_STICKING : CM_GROUP_ATTRACTOR;
    free(rest);
    return CM_OK;
}

cm_status cm_scm_describe(const cm_model *model, const cm_lattice *lat, const cm_region *r,
                          cm_group_info **groups, uint64_t *sink_cells, char *msg, size_t msg_size)
{
    *groups = calloc((size_t)r->ngroups + 1, sizeof **groups);
    if (!*groups)
        return cm_fail(CM_ENOMEM, msg, msg_size, "out of memory for %u groups", r->ngroups);
    cm_status st = cm_scm_groups(r, lat, *groups, sink_cells);
    if (st == CM_OK)
        st = cm_scm_label_groups(model, lat, r, *groups, r->ngroups, msg, msg_size);
    return st;
}

/* What is wrong with cell i's group alone, or NULL. */
static const char *bad_group(uint64_t nexits, uint32_t g, uint32_t max_group, bool node_refs)
{
    if (g == 0 || (g < CM_NODE_REF && g <= max_group))
        return NULL;
    if (node_refs && g >= CM_NODE_REF && g - CM_NODE_REF < nexits)
        return NULL;
    return "its group is no group of the file";
}

cm_status cm_groups_check(const uint32_t *group, uint64_t ncells, uint64_t nexits,
                          uint32_t max_group, char *msg, size_t msg_size)
{
    for (uint64_t i = 0; i < ncells; i++) {
        const char *why = bad_group(nexits, group[i], max_group, true);
        if (why)
            return cm_fail(CM_EFORMAT, msg, msg_size, "cell %llu: %s", (unsigned long long)i,
                           why);
    }
    return CM_OK;
}

/* What is wrong with cell i given its image, or NULL. Exit cells are
 * checked for their own node here; their numbering by the caller. */
static const char *bad_cell(const cm_region *r, uint64_t i, uint32_t max_group, bool node_refs)
{
    const uint32_t m = r->image[i], g = r->group[i], s = r->step[i];
    const char *why = bad_group(r->nexits, g, max_group, node_refs);
    if (why)
        return why;
    if (m == CM_IMAGE_SINK)
        return g == 0 && s == 1 ? NULL : "its image is the sink but its group or step is not";
    if (m < r->ncells) {
        if (s == 0)
            return g != 0 && g < CM_NODE_REF && r->step[m] == 0 && r->group[m] == g
                       ? NULL
                       : "a periodic cell whose image is not on its cycle";
        return r->group[m] == g && r->step[m] == s - 1 ? NULL
                                                       : "its group or step is not its image's";
    }
    const int64_t e = cm_image_exit_index(m);
    if (e < 0 || (uint64_t)e >= r->nexits)
        return "its image is no cell of the region and none of its exits";
    if (node_refs && (g != (CM_NODE_REF | (uint32_t)e) || s != 1))
        return "an exit cell that is not its own node";
    return NULL;
}

/* The cells of one part of a region checked: the first bad one (or
 * UINT64_MAX) and why; its exits must be numbered consecutively from its
 * first (*first_exit, or -1 if it has none; *exits of them). */
typedef struct check_part {
    uint64_t bad, exits;
    int64_t first_exit;
    const char *why;
} check_part;

static void check_cells(const cm_region *r, uint64_t from, uint64_t to, uint32_t max_group,
                        bool node_refs, check_part *p)
{
    *p = (check_part){UINT64_MAX, 0, -1, NULL};
    for (uint64_t i = from; i < to; i++) {
        const char *why = bad_cell(r, i, max_group, node_refs);
        const int64_t e = cm_image_exit_index(r->image[i]);
        if (!why && e >= 0) {
            if (p->first_exit < 0)
                p->first_exit = e;
            else if (e != p->first_exit + (int64_t)p->exits)
                why = "its exit is not the region's next one (exits are numbered in cell order)";
            p->exits++;
        }
        if (why) {
            p->bad = i;
            p->why = why;
            return;
        }
    }
}

/* Exit targets: outside the box, inside the world. */
static cm_status check_exit_targets(const cm_region *r, char *msg, size_t msg_size)
{
    const int dim = r->box.dim;
    for (uint64_t e = 0; e < r->nexits; e++) {
        const int64_t *t = r->exit_target + e * (uint64_t)dim;
        bool inside_world = true;
        for (int d = 0; d < dim; d++)
            inside_world = inside_world && t[d] > -CM_WORLD_LIMIT && t[d] < CM_WORLD_LIMIT;
        if (!inside_world || cm_box_contains(&r->box, t))
            return cm_fail(CM_EFORMAT, msg, msg_size, "exit %llu: its target is %s",
                           (unsigned long long)e,
                           inside_world ? "inside the region" : "outside the world");
    }
    return CM_OK;
}

enum { CHECK_PARTS = 64 };

cm_status cm_region_check(const cm_region *r, uint32_t max_group, bool node_refs, int threads,
                          char *msg, size_t msg_size)
{
    check_part parts[CHECK_PARTS];
    const uint64_t n = r->ncells, per = n / CHECK_PARTS + 1;
#pragma omp parallel for num_threads(threads > 0 ? threads : 1) schedule(dynamic, 1) if (n > 65536)
    for (int k = 0; k < CHECK_PARTS; k++) {
        const uint64_t from = (uint64_t)k * per < n ? (uint64_t)k * per : n;
        const uint64_t to = from + per < n ? from + per : n;
        check_cells(r, from, to, max_group, node_refs, &parts[k]);
    }
    uint64_t next_exit = 0;
    for (int k = 0; k < CHECK_PARTS; k++) { /* the first damage in cell order */
        const check_part *p = &parts[k];
        if (!p->why && p->exits && p->first_exit != (int64_t)next_exit)
            return cm_fail(CM_EFORMAT, msg, msg_size,
                           "exit %lld follows exit %lld (exits are numbered in cell order)",
                           (long long)p->first_exit, (long long)next_exit - 1);
        if (p->why)
            return cm_fail(CM_EFORMAT, msg, msg_size, "cell %llu: %s", (unsigned long long)p->bad,
                           p->why);
        next_exit += p->exits;
    }
    if (next_exit != r->nexits)
        return cm_fail(CM_EFORMAT, msg, msg_size, "%llu exits recorded, %llu found in the cells",
                       (unsigned long long)r->nexits, (unsigned long long)next_exit);
    return check_exit_targets(r, msg, msg_size);
}
