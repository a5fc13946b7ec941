/* Checks before an observer session's first trial (see observer_checks.h). */
#include "calib/observer_checks.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "calib/afc_layout.h"
#include "calib/trial_io.h"
#include "calib/observer_trials.h"
#include "core/file_write.h"
#include "results/csflut/csflut.h"

void obs_default_axes(const csf_geometry *g, csf_obs_settings *s, int quiet)
{
    if (s->n_freqs == 0) {
        /* Frequencies are constant in angle space; on a flat screen pixels per degree are lowest
         * at the centre, so the centre's Nyquist limit caps every position. */
        double nyq = csf_geometry_nyquist_cpd_any(g, 0, 0);
        for (int i = 0; i < 6; i++) {
            double f = 0.5 * pow(32.0, i / 5.0);
            f = csf_round9(f);
            if (f <= nyq) s->freqs[s->n_freqs++] = f;
            else if (!quiet)
                fprintf(stderr,
                        "csfcal: observer: %.3g cpd dropped: above the display's Nyquist "
                        "limit of %.3g cpd\n",
                        f, nyq);
        }
    }
    if (s->n_eccs == 0) {
        static const double e[] = {0, 5, 10, 20};
        double reach = 0;
        for (int a = 0; a < 360; a += 5) {
            double m = csf_geometry_max_ecc(g, a);
            if (m > reach) reach = m;
        }
        for (int i = 0; i < 4; i++) {
            if (e[i] + 3 * GABOR_SIGMA_DEG <= reach) s->eccs[s->n_eccs++] = e[i];
            else if (!quiet)
                fprintf(stderr,
                        "csfcal: observer: %g deg dropped: the screen reaches %.3g deg "
                        "(a patch needs %g deg beyond its centre)\n",
                        e[i], reach, 3 * GABOR_SIGMA_DEG);
        }
    }
}

int obs_cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* ---- checks before the first trial ---------------------------------------------------------- */

/* Output paths, before anything is measured: a session that cannot write its table at the end
 * would have cost the person the whole session. Usage errors (exit status 2). */
csf_status obs_check_outputs(const csf_obs_options *opt, csf_error *err)
{
    csf_status st = csf_check_output_path(opt->out_path, "threshold table", err);
    if (st == CSF_OK && opt->plot_path) {
        const char *ext = strrchr(opt->plot_path, '.');
        if (!ext || (strcasecmp(ext, ".png") && strcasecmp(ext, ".pdf") && strcasecmp(ext, ".svg")))
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "--plot %s: unknown plot format '%s' (allowed "
                                 ".png, .pdf, .svg)",
                                 opt->plot_path, ext ? ext : "(none)");
        if (strcmp(opt->plot_path, opt->out_path) == 0)
            return csf_error_set(err, CSF_E_INVALID_ARG, "--plot and --out are both %s: give two files",
                                 opt->out_path);
        st = csf_check_output_path(opt->plot_path, "report plot", err);
    }
    if (st != CSF_OK && st != CSF_E_NOMEM) {
        err->code = CSF_E_INVALID_ARG;
        return CSF_E_INVALID_ARG;
    }
    return st;
}

/* One grid axis: values in range and strictly increasing (the table format's rule; equal values
 * would measure one cell twice and leave the table unwritable). A new session's values are sorted
 * first (sort = 1); a stored session's must already be in order. */
static csf_status check_axis(const char *opt, const char *unit, double *v, int n, double lo, double hi,
                             int sort, csf_error *err)
{
    if (n < 1 || n > CSF_OBS_MAX_AXIS)
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s: %d values (allowed 1 to %d)", opt, n,
                             CSF_OBS_MAX_AXIS);
    for (int i = 0; i < n; i++)
        if (!(v[i] >= lo && v[i] <= hi))
            return csf_error_set(err, CSF_E_INVALID_ARG, "%s: %g %s is out of range (allowed %g to %g %s)",
                                 opt, v[i], unit, lo, hi, unit);
    if (sort) qsort(v, (size_t)n, sizeof *v, obs_cmp_d);
    for (int i = 1; i < n; i++) {
        if (v[i] == v[i - 1])
            return csf_error_set(err, CSF_E_INVALID_ARG, "%s: %g %s is given twice (each value once)", opt,
                                 v[i], unit);
        if (!(v[i] > v[i - 1]))
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "%s: %g %s comes after %g %s (values must "
                                 "increase)",
                                 opt, v[i], unit, v[i - 1], unit);
    }
    /* and what the table writer will demand of it at the end (neighbours it can tell apart) */
    if (strcmp(unit, "deg/s") == 0) return CSF_OK; /* velocity: checked with the grid (obs_check_settings) */
    double thr[CSF_OBS_MAX_AXIS];
    for (int i = 0; i < n; i++) thr[i] = 0.01;
    double other = 1.0;
    csflut_build b;
    memset(&b, 0, sizeof b);
    int is_freq = strcmp(unit, "cpd") == 0;
    b.n_freq = is_freq ? n : 1;
    b.n_ecc = is_freq ? 1 : n;
    b.freq_cpd = is_freq ? v : &other;
    b.ecc_deg = is_freq ? &other : v;
    b.threshold = thr;
    csflut_diag d;
    memset(&d, 0, sizeof d);
    if (csflut_validate_build(&b, &d) != CSFLUT_OK)
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s: %s", opt, d.message);
    return CSF_OK;
}

csf_status obs_check_settings(csf_obs_settings *set, int sort, csf_error *err)
{
    if (strcmp(set->method, "bayes") && strcmp(set->method, "fade") && strcmp(set->method, "2afc"))
        return csf_error_set(err, CSF_E_INVALID_ARG, "--method %s: unknown (bayes, fade, 2afc)", set->method);
    int sim = strncmp(set->observer, "sim", 3) == 0 && (set->observer[3] == '\0' || set->observer[3] == ':');
    int human =
        strncmp(set->observer, "human", 5) == 0 && (set->observer[5] == '\0' || set->observer[5] == ':');
    if (!sim && !human)
        return csf_error_set(err, CSF_E_INVALID_ARG,
                             "--observer %s: expected sim[:key=value,...] or human[:NAME]", set->observer);
    csf_status st = check_axis("--freqs", "cpd", set->freqs, set->n_freqs, 0.01, 200, sort, err);
    if (st == CSF_OK) st = check_axis("--eccs", "deg", set->eccs, set->n_eccs, 0, 80, sort, err);
    if (st == CSF_OK && set->n_vels > 0)
        st = check_axis("--velocities", "deg/s", set->vels, set->n_vels, 0, CSF_PROC_MAX_VELOCITY_DPS, sort,
                        err);
    if (st == CSF_OK && !(set->drift_direction >= -1 && set->drift_direction <= 1))
        st = csf_error_set(err, CSF_E_INVALID_ARG, "--drift-direction: %d is not -1, 0 or 1",
                           set->drift_direction);
    if (st == CSF_OK && !(set->trials >= 1 && set->trials <= 5000))
        st = csf_error_set(err, CSF_E_INVALID_ARG, "--trials: %d is out of range (allowed 1 to 5000)",
                           set->trials);
    if (st == CSF_OK && !(set->practice >= 0 && set->practice <= 50))
        st = csf_error_set(err, CSF_E_INVALID_ARG, "--practice: %d is out of range (allowed 0 to 50)",
                           set->practice);
    if (st == CSF_OK && !(set->break_every >= 1 && set->break_every <= 5000))
        st = csf_error_set(err, CSF_E_INVALID_ARG, "--break-every: %d is out of range (allowed 1 to 5000)",
                           set->break_every);
    return st;
}

/* Every cell of the grid, and the practice grating, can be drawn on this screen: checked before
 * the first trial, so a session never stops at a cell it cannot show. The messages name the
 * limit: how far the screen reaches, or the local Nyquist limit. */
csf_status obs_check_grid_on_screen(csf_presenter *pres, const csf_config *cfg, const csf_obs_settings *set,
                                    int practice_left, double mean_lum, csf_error *err)
{
    const csf_geometry *g = csf_presenter_geometry(pres);
    const double low_cpd = 0.05; /* far below any Nyquist limit: only the place decides */
    csf_error why;
    csf_error_clear(&why);
    if (!obs_cell_fits(pres, low_cpd, 0, mean_lum, NULL, &why))
        return csf_error_set(err, CSF_E_INVALID_ARG, "this display cannot show the test gratings: %s",
                             why.msg);
    double reach = 0, reach_polar = 0;
    for (int a = 0; a < 360; a++) {
        double m = csf_geometry_max_ecc(g, a);
        if (m > reach) {
            reach = m;
            reach_polar = a;
        }
    }
    const double patch_deg = CSF_AFC_PATCH_RADIUS_SIGMAS * GABOR_SIGMA_DEG;
    for (int e = 0; e < set->n_eccs; e++) {
        double ecc = set->eccs[e];
        if (obs_cell_fits(pres, low_cpd, ecc, mean_lum, NULL, NULL)) continue;
        /* the largest eccentricity where a patch fits somewhere: bisection (fitting shrinks with
         * eccentricity) */
        double lo = 0, hi = ecc;
        for (int i = 0; i < 30; i++) {
            double mid = 0.5 * (lo + hi);
            if (obs_cell_fits(pres, low_cpd, mid, mean_lum, NULL, NULL)) lo = mid;
            else hi = mid;
        }
        return csf_error_set(
            err, CSF_E_INVALID_ARG,
            "--eccs: %g deg does not fit on this screen: it reaches %.3g deg from the "
            "fixation mark at most (towards polar angle %g deg; %g x %g mm seen from %g mm), "
            "a Gabor patch needs %g deg around its centre, so the largest eccentricity "
            "is %.3g deg",
            ecc, reach, reach_polar, cfg->screen_width_mm, cfg->screen_height_mm, cfg->viewing_distance_mm,
            patch_deg, floor(lo * 100) / 100);
    }
    for (int e = 0; e < set->n_eccs; e++)
        for (int f = 0; f < set->n_freqs; f++) {
            double ecc = set->eccs[e], freq = set->freqs[f];
            if (obs_cell_fits(pres, freq, ecc, mean_lum, NULL, NULL)) continue;
            double lo = low_cpd, hi = freq;
            for (int i = 0; i < 30; i++) {
                double mid = sqrt(lo * hi);
                if (obs_cell_fits(pres, mid, ecc, mean_lum, NULL, NULL)) lo = mid;
                else hi = mid;
            }
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "--freqs: %g cpd at %g deg is above the local Nyquist limit of %.3g cpd "
                                 "there (0.5 cycle/pixel; %d x %d px over %g x %g mm seen from %g mm): "
                                 "lower the frequency or increase the viewing distance",
                                 freq, ecc, floor(lo * 1000) / 1000, cfg->screen_width_px,
                                 cfg->screen_height_px, cfg->screen_width_mm, cfg->screen_height_mm,
                                 cfg->viewing_distance_mm);
        }
    if (practice_left > 0) {
        csf_stimulus ps;
        obs_make_stimulus(&ps, PRACTICE_FREQ, 0, 0, PRACTICE_CONTRAST, mean_lum);
        if (csf_presenter_validate(pres, &ps, &why) != CSF_OK)
            return csf_error_set(err, CSF_E_INVALID_ARG,
                                 "--practice: practice trials show %g cpd at the "
                                 "fixation mark, which this display cannot: %s; give --practice 0",
                                 PRACTICE_FREQ, why.msg);
    }
    return CSF_OK;
}

/* ---- display profile across --resume --------------------------------------------------------- */

/* The session's profile history, kept as a "profile_change" artifact whose newest copy holds all
 * of it: one line per profile, "TRIAL PROFILE_ID" (the stored trial count from which it was
 * used). Absent when the profile never changed. */
#define PROFILE_HISTORY_KIND "profile_change"

static char *profile_history(csf_store *store, int64_t sid)
{
    void *blob = NULL;
    size_t len = 0;
    csf_error e;
    if (csf_store_get_artifact(store, sid, PROFILE_HISTORY_KIND, &blob, &len, NULL, 0, &e) != CSF_OK)
        return NULL;
    return blob; /* NUL-terminated by the store */
}

/* The profile id the session used last: the history's last line, else the one it began with. */
static void last_profile(const char *history, const char *began, char *out, size_t len)
{
    snprintf(out, len, "%s", began);
    if (!history) return;
    const char *line = history;
    while (*line) {
        const char *nl = strchr(line, '\n');
        size_t n = nl ? (size_t)(nl - line) : strlen(line);
        const char *sp = memchr(line, ' ', n);
        if (sp && n > (size_t)(sp + 1 - line))
            snprintf(out, len, "%.*s", (int)(n - (size_t)(sp + 1 - line)), sp + 1);
        if (!nl) break;
        line = nl + 1;
    }
}

/* On --resume: the profile this run has must be the one the session used last, unless the user
 * said --allow-profile-change; then the change is added to the history. */
csf_status obs_check_profile_on_resume(csf_store *store, int64_t sid, const char *began, int n_stored,
                                       const csf_display_profile *now, const csf_config *cfg, int allow,
                                       int quiet, csf_error *err)
{
    char *hist = profile_history(store, sid);
    char last[256];
    last_profile(hist, began, last, sizeof last);
    const char *id = csf_profile_id(now);
    csf_status st = CSF_OK;
    /* Sessions stored before the settings kept the profile id have only the session row's
     * profile_id, cut at 127 characters. */
    size_t cmp_len =
        !hist && strlen(last) == sizeof((csf_session_info *)0)->profile_id - 1 ? strlen(last) : sizeof last;
    if (strncmp(last, id, cmp_len) == 0) goto done;
    if (!allow) {
        st = csf_error_set(err, CSF_E_INVALID_ARG,
                           "--resume %lld: the session was measured with display profile '%s', this run "
                           "has '%s' (%s): one table would mix two displays. Resume with --profile FILE of "
                           "'%s', or give --allow-profile-change to go on with '%s' (recorded in the "
                           "session and the table)",
                           (long long)sid, last, id,
                           cfg->display_profile[0] ? cfg->display_profile
                                                   : "the default display model, no --profile",
                           last, id);
        goto done;
    }
    char entry[400];
    snprintf(entry, sizeof entry, "%d %s\n", n_stored, id);
    size_t hl = hist ? strlen(hist) : 0;
    char first[300] = "";
    if (!hist) snprintf(first, sizeof first, "0 %s\n", began);
    size_t total = strlen(first) + hl + strlen(entry) + 1;
    char *blob = malloc(total);
    if (!blob) {
        st = csf_error_set(err, CSF_E_NOMEM, "out of memory");
        goto done;
    }
    snprintf(blob, total, "%s%s%s", first, hist ? hist : "", entry);
    st = csf_store_add_artifact(store, sid, PROFILE_HISTORY_KIND, "", blob, strlen(blob), err);
    free(blob);
    if (st == CSF_OK && !quiet)
        fprintf(stderr,
                "csfcal: observer: session %lld goes on with display profile '%s' from trial %d (it "
                "was measured with '%s'): --allow-profile-change, recorded in the session and the "
                "table\n",
                (long long)sid, id, n_stored, last);
done:
    free(hist);
    return st;
}

/* The table's display_profile_id: the one profile, or every profile with the trial it began at. */
void obs_table_profile_id(csf_store *store, int64_t sid, const char *id, char *out, size_t len)
{
    char *hist = profile_history(store, sid);
    if (!hist) {
        snprintf(out, len, "%s", id);
        return;
    }
    size_t n = 0;
    out[0] = '\0';
    for (const char *line = hist; *line && n < len;) {
        const char *nl = strchr(line, '\n');
        size_t l = nl ? (size_t)(nl - line) : strlen(line);
        const char *sp = memchr(line, ' ', l);
        if (sp)
            n += (size_t)snprintf(out + n, len - n, "%s%.*s from trial %.*s", n ? ", " : "",
                                  (int)(l - (size_t)(sp + 1 - line)), sp + 1, (int)(sp - line), line);
        if (!nl) break;
        line = nl + 1;
    }
    if (n < len) snprintf(out + n, len - n, " (--allow-profile-change)");
    free(hist);
}
