/* The tidy trial export of a study (see study_export.h). */
#include "studies/study_export.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/file_write.h"
#include "results/store/store.h"
#include "studies/study_plan.h"
#include "studies/study_sessions.h"

/* Every column this export writes besides the conditions file's own, in order. */
const char *const csf_study_export_columns[] = {
    "study", "version", "study_sha256", "participant", "session", "session_finished", "participant_index",
    "counterbalance_row", "session_experimenter", "session_notes", "trial", "block", "practice", "condition",
    /* the conditions file's columns go here */
    "stim_kind", "stim_freq_cpd", "stim_ecc_deg", "stim_polar_deg", "stim_orientation_deg", "stim_sigma_deg",
    "stim_velocity_dps", "stim_mean_lum_cdm2", "contrast_requested", "contrast_shown_mean",
    "contrast_shown_max", "frames_planned", "frames_shown", "frames_missed", "target", "image_first",
    "image_first_sha256", "image_second", "image_second_sha256", "response", "correct", "rt_s", "onset_s",
    "valid", "flags", NULL};
#define N_LEAD 14 /* columns before the conditions file's */

/* One session's material, as the report's walk loads it (studies/study_sessions.h). */
typedef csf_study_session_data sess;

/* A text cell, quoted only when it holds a comma, a quote or a line end. */
static void put_cell(FILE *fp, const char *s)
{
    if (!strpbrk(s, ",\"\n\r")) {
        fputs(s, fp);
        return;
    }
    fputc('"', fp);
    for (const char *p = s; *p; p++) {
        if (*p == '"') fputc('"', fp);
        fputc(*p, fp);
    }
    fputc('"', fp);
}

static void put_text(FILE *fp, const char *s)
{
    fputc(',', fp);
    put_cell(fp, s);
}

/* The shortest decimal that reads back as the same double; missing: an empty cell. */
static void put_num(FILE *fp, double v)
{
    fputc(',', fp);
    if (isnan(v)) return;
    if (isinf(v)) {
        fputs(v > 0 ? "Inf" : "-Inf", fp);
        return;
    }
    char buf[40];
    for (int digits = 15; digits <= 17; digits++) {
        snprintf(buf, sizeof buf, "%.*g", digits, v);
        if (strtod(buf, NULL) == v) break;
    }
    fputs(buf, fp);
}

static void put_header(FILE *fp, const csf_study_table *t)
{
    for (int i = 0; i < N_LEAD; i++) fprintf(fp, "%s%s", i ? "," : "", csf_study_export_columns[i]);
    for (int i = 0; i < t->n_columns; i++) put_text(fp, t->names[i]);
    for (int i = N_LEAD; csf_study_export_columns[i]; i++) fprintf(fp, ",%s", csf_study_export_columns[i]);
    fputc('\n', fp);
}

static const char *kind_name(csf_cond_kind k)
{
    return k == CSF_COND_IMAGE ? "image" : k == CSF_COND_GRATING ? "grating" : "gabor";
}

/* The image shown first and second (same/different: the pair's order; 2ifc: b in the target
 * interval), by their names in the conditions file, with their hashes. */
static void put_images(FILE *fp, const sess *d, const csf_study_condition *c, const csf_study_trial *pt)
{
    if (c->kind != CSF_COND_IMAGE) {
        fputs(",,,,", fp);
        return;
    }
    int first, second;
    if (d->study->design == CSF_DESIGN_SAME_DIFF) {
        first = pt->order;
        second = pt->target ? !pt->order : pt->order;
    } else {
        first = pt->target == 0;
        second = pt->target == 1;
    }
    const char *path[2] = {c->image_a, c->image_b};
    int which[2] = {first, second};
    for (int k = 0; k < 2; k++) {
        char name[1024];
        csf_study_image_name(d->study, path[which[k]], name, sizeof name);
        put_text(fp, name);
        const char *h = "";
        for (int i = 0; !d->x->legacy && i < d->x->identity.n_images; i++)
            if (!strcmp(d->x->identity.images[i].name, name)) h = d->x->identity.images[i].sha256;
        put_text(fp, h);
    }
}

static int target_of(const csf_study *s, const csf_study_trial *pt)
{
    return s->design == CSF_DESIGN_2AFC || s->design == CSF_DESIGN_2IFC ? pt->target + 1 : pt->target;
}

static void put_trial(FILE *fp, const char *study, const sess *d, const csf_trial *t)
{
    const csf_study *s = d->study;
    const csf_study_trial *pt = &d->plan[t->seq];
    const csf_study_condition *c = &s->conds[pt->cond];
    int forced = s->design == CSF_DESIGN_2AFC || s->design == CSF_DESIGN_2IFC;
    put_cell(fp, study);
    fprintf(fp, ",%d", d->x->version);
    put_text(fp, d->x->key);
    put_text(fp, d->x->participant);
    fprintf(fp, ",%lld,%d,%d,", (long long)d->x->id, d->x->state == CSF_SESSION_FINISHED,
            d->x->participant_index);
    if (s->latin) fprintf(fp, "%d", csf_study_latin_row(s, d->x->participant_index, NULL));
    put_text(fp, d->x->experimenter);
    put_text(fp, d->x->notes);
    fprintf(fp, ",%d,%d,%d", t->seq, pt->practice ? 0 : pt->block + 1, pt->practice);
    put_text(fp, c->label);
    for (int i = 0; i < d->table.n_columns; i++) put_text(fp, CSF_STUDY_CELL(&d->table, pt->cond, i));
    put_text(fp, kind_name(c->kind));
    double p[] = {t->freq_cpd,
                  t->ecc_deg,
                  t->polar_deg,
                  t->orientation_deg,
                  t->sigma_deg,
                  t->velocity_dps,
                  t->mean_lum_cdm2,
                  t->contrast_requested,
                  t->contrast_shown_mean,
                  t->contrast_shown_max};
    for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) put_num(fp, p[i]);
    fprintf(fp, ",%d,%d,%d,%d", t->frames_planned, t->frames_shown, t->frames_missed, target_of(s, pt));
    put_images(fp, d, c, pt);
    int correct = forced ? t->response == t->signal_interval : (t->response == 1) == !t->is_catch;
    fprintf(fp, ",%d", t->response);
    if (t->valid) fprintf(fp, ",%d", correct);
    else fputc(',', fp);
    put_num(fp, t->rt_s);
    put_num(fp, t->has_onset ? t->onset_s : NAN);
    fprintf(fp, ",%d", t->valid);
    put_text(fp, t->flags);
    fputc('\n', fp);
}

/* The rows of the sessions d[0..n) (of one participant when only is set) into path. */
static csf_status write_csv(const char *path, const char *study, const sess *d, int n, const char *only,
                            int *rows, csf_error *err)
{
    csf_atomic_file af = {0};
    csf_status st = csf_atomic_open(&af, path, "study trial export", err);
    if (st != CSF_OK) return st;
    put_header(af.fp, &d[0].table);
    for (int i = 0; i < n; i++) {
        if (only && strcmp(d[i].x->participant, only)) continue;
        for (size_t j = 0; j < d[i].n_trials; j++) {
            const csf_trial *t = &d[i].trials[j];
            if (t->seq < 0 || t->seq >= d[i].n_plan) continue;
            put_trial(af.fp, study, &d[i], t);
            if (rows) (*rows)++;
        }
    }
    return csf_atomic_commit(&af, err);
}

/* Every session must share the first one's conditions columns: the rows go under one header. */
static csf_status same_columns(const sess *d, int n, csf_error *err)
{
    for (int i = 1; i < n; i++) {
        int same = d[i].table.n_columns == d[0].table.n_columns;
        for (int k = 0; same && k < d[0].table.n_columns; k++)
            same = !strcmp(d[i].table.names[k], d[0].table.names[k]);
        if (!same)
            return csf_error_set(err, CSF_E_FORMAT,
                                 "session %lld's conditions file has other columns than session "
                                 "%lld's",
                                 (long long)d[i].x->id, (long long)d[0].x->id);
    }
    return CSF_OK;
}

/* One file per participant in dir: PARTICIPANT.csv. A stored code names a file only when it keeps
 * to the participant pattern a run enforces (a row written past csfcal may not). */
static csf_status per_participant(const char *dir, const char *study, const sess *d, int n, csf_error *err)
{
    if (mkdir(dir, 0777) != 0 && errno != EEXIST)
        return csf_error_set(err, CSF_E_IO, "--per-participant %s: cannot make the folder: %s", dir,
                             strerror(errno));
    csf_status st = CSF_OK;
    for (int i = 0; st == CSF_OK && i < n; i++) {
        int seen = 0;
        for (int j = 0; j < i; j++) seen |= !strcmp(d[j].x->participant, d[i].x->participant);
        if (seen) continue;
        const char *p = d[i].x->participant;
        if (!csf_study_participant_ok(p)) {
            char shown[300];
            csf_store_printable(p, shown, sizeof shown);
            return csf_error_set(err, CSF_E_FORMAT, "participant '%s' (session %lld) cannot name a file",
                                 shown, (long long)d[i].x->id);
        }
        char path[2048];
        snprintf(path, sizeof path, "%s/%s.csv", dir, p);
        st = write_csv(path, study, d, n, p, NULL, err);
    }
    return st;
}

csf_status csf_study_export(const char *store_path, const char *study, int version, const char *out,
                            const char *per_participant_dir, int *n_rows, csf_error *err)
{
    *n_rows = 0;
    csf_store *store = NULL;
    csf_status st = csf_store_open_readonly(store_path, &store, err);
    if (st != CSF_OK) return st;
    csf_study_selection sel;
    st = csf_study_select(store, study, version, &sel, err);
    if (st != CSF_OK) {
        csf_store_close(store);
        return st;
    }
    sess *d = NULL;
    int n = 0;
    st = csf_study_sessions_load(store, &sel, 1, NULL, &d, &n, err);
    if (st == CSF_OK && !n)
        st = csf_error_set(err, CSF_E_NOT_FOUND, "study %s: no session holds its study files", sel.name);
    if (st == CSF_OK) st = same_columns(d, n, err);
    if (st == CSF_OK) st = write_csv(out, sel.name, d, n, NULL, n_rows, err);
    if (st == CSF_OK && per_participant_dir) st = per_participant(per_participant_dir, sel.name, d, n, err);
    csf_study_session_data_free(d, n);
    csf_study_selection_free(&sel);
    csf_store_close(store);
    return st;
}
