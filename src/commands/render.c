/* pfx render FILE... -o DIR: for each effect the frames (PNG or EXR),
 * their manifest and depfile, and with the options an atlas, motion
 * vectors and a preview; skipped when the manifest proves it up to date. */
#include "commands/commands.h"

#include <string.h>
#include <unistd.h>

#include "jobs/atlas_job.h"
#include "jobs/motion_job.h"
#include "jobs/output_names.h"
#include "jobs/parallel.h"
#include "jobs/preview.h"
#include "jobs/progress.h"
#include "jobs/slice.h"

/* A slice: its part of the job's range, and a manifest of its own, so
 * that slices may share a directory. */
static void take_slice(const pfx_cli *o, pfx_render_job *job, char *manifest, size_t size) {
    if (!o->slices)
        return;
    const long all_first = job->first, all_last = job->last;
    pfx_slice_range_step(all_first, all_last, o->every, o->slice, o->slices, &job->first,
                         &job->last);
    snprintf(manifest, size, "%s/%s.slice-%04ld-of-%04ld.manifest.json", job->dir, job->stem,
             o->slice, o->slices);
}

/* The run's settings in its manifest (renderer, frame format, slice,
 * atlas, preview, motion vectors): what decides the bake key. An atlas that
 * cannot be made fails here, before any frame. */
static bool describe_render(const pfx_render_job *job, const pfx_cli *o, long all_first,
                            long all_last, pfx_delivery *dl, pfx_atlas_layout *atlas,
                            pfx_mv_meta *mv, pfx_diags *run) {
    pfx_manifest_set_string(dl->now, "renderer", pfx_renderer_name(job->renderer));
    if (o->frames_as != PFX_FRAME_PNG) /* PNG, the default, keeps the keys it had */
        pfx_manifest_set_string(dl->now, "format", pfx_frame_format_name(o->frames_as));
    if (o->every > 1) /* --frames A:B:S; every frame, the default, keeps the keys too */
        pfx_manifest_set_number(dl->now, "step", (double)o->every);
    if (o->slices)
        pfx_manifest_set_slice(dl->now, o->slice, o->slices, all_first, all_last);
    /* Premultiplied frames make a premultiplied sheet and a preview
     * converted from them; PNG, the straight default, keeps its keys. */
    const bool premultiplied = job->effect->alpha_mode == PFX_ALPHA_PREMULTIPLIED;
    if (premultiplied)
        pfx_manifest_set_number(dl->now, "premultiplied", 1);
    atlas->premultiplied = premultiplied;
    if (o->atlas) {
        /* The sheet's size is known now but for --crop, which only makes
         * it smaller: one that cannot be made fails before any frame. */
        pfx_atlas_layout check = *atlas;
        check.frame_w = job->effect->width;
        check.frame_h = job->effect->height;
        check.frames = (int)((job->last - job->first) / o->every + 1);
        if (!pfx_atlas_layout_resolve(&check, run))
            return false;
        pfx_atlas_job_describe(atlas, dl->now);
    }
    if (o->preview) {
        /* A preview that cannot be made fails before any frame too. */
        pfx_preview p = {.path = o->preview};
        if (!pfx_preview_check(&p, job->effect->width, job->effect->height, run))
            return false;
        pfx_manifest_set_string(dl->now, "preview", o->preview);
        if (o->preview_quality >= 0)
            pfx_manifest_set_number(dl->now, "preview_quality", o->preview_quality);
    }
    if (o->motion_vectors)
        pfx_mv_describe(mv, dl->now);
    return true;
}

/* Every file the run will write, as write_extras and the frame loop name
 * them: checked before any work (jobs/output_names.h). */
static bool check_outputs(const pfx_render_job *job, const pfx_cli *o, const pfx_delivery *dl,
                          pfx_diags *run) {
    pfx_output_names names = {0};
    const char *dir = job->dir, *stem = job->stem;
    char path[4600];
    /* --frames A:B:S writes every S-th frame: only those are checked. */
    snprintf(path, sizeof path, "%s/%s_", dir, stem);
    char ext[16];
    snprintf(ext, sizeof ext, ".%s", pfx_frame_format_name(o->frames_as));
    pfx_output_names_add_numbered(&names, path, 4, ext, job->first, job->last,
                                  o->every > 1 ? o->every : 1);
    if (o->motion_vectors) {
        pfx_output_names_add_frames(&names, dir, stem, "_mv_", job->first, job->last, "png");
        snprintf(path, sizeof path, "%s/%s_mv%s", dir, stem, o->atlas ? "_atlas.png" : ".json");
        pfx_output_names_add(&names, path);
    }
    if (o->atlas) {
        snprintf(path, sizeof path, "%s/%s_atlas.png", dir, stem);
        pfx_output_names_add(&names, path);
        snprintf(path, sizeof path, "%s/%s_atlas.json", dir, stem);
        pfx_output_names_add(&names, path);
    }
    pfx_output_names_add(&names, o->preview);
    bool ok = pfx_cli_check_outputs(dl, &names, run);
    pfx_output_names_free(&names);
    return ok;
}

/* After the frames: each one listed in the manifest, then the motion
 * vectors' list and sidecar, the atlas, the preview, and the manifest
 * itself with the depfile. */
static bool write_extras(const pfx_render_job *job, const pfx_cli *o, const char *stem,
                         pfx_delivery *dl, pfx_atlas_layout *atlas, const pfx_mv_meta *mv,
                         pfx_diags *run) {
    const char *dir = job->dir;
    for (long f = job->first; f <= job->last; f += o->every) {
        char name[300];
        snprintf(name, sizeof name, "%s_%04ld.%s", stem, f, pfx_frame_format_name(o->frames_as));
        if (!pfx_manifest_add_output(dl->now, dir, name, run))
            return false;
    }
    if (o->motion_vectors &&
        (!pfx_mv_add_outputs(dl->now, dir, stem, job->first, job->last, run) ||
         (!o->atlas && !pfx_mv_sidecar_run(dir, stem, job->first, job->last, mv, dl->now, run))))
        return false;
    if (o->atlas && !pfx_atlas_job_run(dir, stem, job->first, job->last, o->every, job->effect->fps,
                                       job->effect->loop, atlas, dl->now, run))
        return false;
    pfx_preview preview = {
        .path = o->preview, .quality = o->preview_quality, .premultiplied = atlas->premultiplied};
    if (o->preview &&
        (!pfx_preview_run(dir, stem, job->first, job->last, o->every, job->effect->fps,
                          job->effect->width, job->effect->height, &preview, run) ||
         !pfx_manifest_add_preview(dl->now, o->preview, run)))
        return false;
    if (!pfx_delivery_finish(dl, run))
        return false;
    return true;
}

/* The one summary line of a render that succeeded. */
static void say_rendered(const pfx_render_job *job, const pfx_cli *o, const char *path,
                         long all_first, long all_last, const pfx_delivery *dl,
                         const pfx_atlas_layout *atlas, const pfx_mv_meta *mv, pfx_diags *run) {
    pfx_sim_note_dropped(job->sim, run);
    if (job->first > job->last)
        fprintf(stderr, "pfx: slice %ld of %ld of '%s' has no frames (%ld frames in all)", o->slice,
                o->slices, path, pfx_cli_frame_count(o, all_first, all_last));
    else if (o->every > 1)
        fprintf(stderr, "pfx: rendered '%s': %ld frames (%ld to %ld, every %ld) in '%s'", path,
                job->frames_done, job->first, job->last, o->every, job->dir);
    else
        fprintf(stderr, "pfx: rendered '%s': %ld frames (%ld to %ld) in '%s'", path,
                job->frames_done, job->first, job->last, job->dir);
    if (o->slices && job->first <= job->last)
        fprintf(stderr, ", slice %ld of %ld", o->slice, o->slices);
    if (o->atlas)
        fprintf(stderr, ", atlas %dx%d of %dx%d", atlas->columns, atlas->rows, atlas->width,
                atlas->height);
    if (o->preview)
        fprintf(stderr, ", preview '%s'", o->preview);
    if (o->motion_vectors)
        fprintf(stderr, ", motion vectors up to %g px", mv->max_px);
    if (dl->stale_removed)
        fprintf(stderr, ", %zu stale removed", dl->stale_removed);
    fputc('\n', stderr);
}

/* Renders one effect file into dir: the whole of `pfx render` for one FILE.
 * `loaded` (when not NULL) hears of the compiled effect first. Returns the
 * exit status. */
static int render_one(const char *path, const char *dir, pfx_renderer_kind kind, const pfx_cli *o,
                      pfx_cli_loaded_fn loaded, void *ctx) {
    pfx_loaded l;
    pfx_effect *e = pfx_cli_load(&l, path, o);
    if (loaded && l.effect)
        loaded(ctx, l.effect);
    int status = EXIT_INVALID;
    pfx_diags run;
    pfx_diags_init_runtime(&run);
    char stem[256], manifest[4096 + 320];
    pfx_cli_file_stem(path, stem, sizeof stem);
    snprintf(manifest, sizeof manifest, "%s/%s.manifest.json", dir, stem);
    pfx_render_job job = {.effect = e,
                          .dir = dir,
                          .stem = stem,
                          .step = o->every,
                          .format = o->frames_as,
                          .progress = !o->quiet && !o->progress_json && isatty(2)};
    pfx_progress progress;
    bool reporting = false;
    pfx_delivery dl = {.dir = dir,
                       .manifest_path = manifest,
                       .depfile = o->depfile,
                       .target = manifest,
                       .force = o->force};
    if (!e)
        goto done;
    if (!pfx_cli_frame_range(e, o, &job.first, &job.last)) {
        status = EXIT_USAGE;
        goto done;
    }
    long all_first = job.first, all_last = job.last;
    take_slice(o, &job, manifest, sizeof manifest);
    if (o->progress_json) {
        pfx_progress_init(&progress, stderr, path, pfx_cli_frame_count(o, job.first, job.last));
        job.on_frame = pfx_progress_frame;
        job.on_frame_ctx = &progress;
        reporting = true;
    }
    if (!pfx_cli_memory_fits(e, job.first, job.last, true, o, &run))
        goto done;
    /* The renderer before the directory: one that cannot start writes
     * nothing. */
    job.renderer = pfx_renderer_create(kind, e->width, e->height, &run);
    if (!job.renderer)
        goto done;
    if (!pfx_delivery_begin(&dl, "render", &run) ||
        !pfx_cli_describe_run(&dl, &l, job.first, job.last, o, &run))
        goto done;
    pfx_atlas_layout atlas = o->atlas_layout;
    pfx_mv_meta mv = {
        .max_px = o->mv_max, .max_given = o->mv_max > 0, .flip_y = o->mv_flip_y, .fps = e->fps};
    if (!describe_render(&job, o, all_first, all_last, &dl, &atlas, &mv, &run) ||
        !check_outputs(&job, o, &dl, &run) || !pfx_cli_make_dirs(dir, &run))
        goto done;
    if (pfx_delivery_up_to_date(&dl) && (!o->preview || access(o->preview, F_OK) == 0)) {
        if (pfx_delivery_skip(&dl, &run)) {
            pfx_cli_say_up_to_date(o, path, dir, &dl);
            status = 0;
        }
        goto done;
    }
    /* --motion-vectors: one scale for the whole sequence, whatever the
     * range, unless --mv-max gives it. */
    if (o->motion_vectors) {
        if (!mv.max_given && !pfx_mv_sequence_max(e, &mv.max_px, &run))
            goto done;
        job.motion = &mv;
        atlas.motion = &mv;
    }
    if (!(o->jobs > 1 ? pfx_render_job_run_parallel(&job, kind, o->jobs, &run)
                      : pfx_render_job_run(&job, &run)))
        goto done;
    if (!write_extras(&job, o, stem, &dl, &atlas, &mv, &run))
        goto done;
    if (!o->quiet)
        say_rendered(&job, o, path, all_first, all_last, &dl, &atlas, &mv, &run);
    status = 0;
done:
    pfx_diags_print(&run, stderr, false);
    if (reporting)
        pfx_progress_finish(&progress, status);
    pfx_diags_free(&run);
    pfx_delivery_free(&dl);
    pfx_renderer_destroy(job.renderer);
    pfx_render_job_free(&job);
    pfx_loaded_free(&l);
    return status;
}

/* pfx render FILE... -o DIR: one file into DIR, several each into
 * DIR/<name>/, one after another (-j works inside each); the exit status is
 * the worst, and the first failure stops the rest unless --keep-going. */
int pfx_cmd_render(const char *const *operands, int count, const pfx_cli *o) {
    return pfx_cli_render_each(operands, count, o, NULL, NULL);
}

int pfx_cli_render_each(const char *const *operands, int count, const pfx_cli *o,
                        pfx_cli_loaded_fn loaded, void *ctx) {
    if (count < 1)
        return pfx_cli_usage_error("%s", "render needs a FILE and -o DIR");
    if (!o->output)
        return pfx_cli_usage_error("%s", "render needs -o DIR");
    int files = count;
    if (files > 1 && o->depfile)
        return pfx_cli_usage_error("%s", "--depfile names one target: give one FILE");
    for (int i = 0; i < count; i++)
        for (int k = 0; k < i; k++) {
            char a[256], b[256];
            pfx_cli_file_stem(operands[i], a, sizeof a);
            pfx_cli_file_stem(operands[k], b, sizeof b);
            if (!strcmp(a, b))
                return pfx_cli_usage_error("two effects would render into '%s': rename one", a);
        }
    /* A stem that is no file name ("..yaml" gives ".", "...yaml" gives
     * "..") would put the outputs in OUT/. or OUT/..: refused before any
     * file is rendered, whatever its place among the FILEs. */
    for (int i = 0; i < count; i++) {
        char stem[256];
        pfx_cli_file_stem(operands[i], stem, sizeof stem);
        if (!*stem || !strcmp(stem, ".") || !strcmp(stem, "..")) {
            fprintf(stderr,
                    "pfx: cannot render '%s': its outputs would be named after '%s', which "
                    "is a directory's name; rename the file\n",
                    operands[i], stem);
            return EXIT_INVALID;
        }
    }
    pfx_renderer_kind kind;
    if (!pfx_cli_renderer_kind(o, &kind))
        return EXIT_USAGE;
    int worst = 0;
    for (int i = 0; i < count; i++) {
        char dir[4096], stem[256];
        pfx_cli_file_stem(operands[i], stem, sizeof stem);
        snprintf(dir, sizeof dir, "%s/%s", o->output, stem);
        int status = render_one(operands[i], files > 1 ? dir : o->output, kind, o, loaded, ctx);
        if (status > worst)
            worst = status;
        if (status && !o->keep_going) {
            if (i + 1 < count)
                fprintf(stderr,
                        "pfx: stopped after '%s' failed; %d file%s not rendered "
                        "(--keep-going renders them)\n",
                        operands[i], count - i - 1, count - i - 1 == 1 ? "" : "s");
            break;
        }
    }
    return worst;
}
