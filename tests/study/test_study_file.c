/* Study files refused before any trial, with the file, line and problem in the message
 * (studies/study_file.h), and the display checks (studies/study_run.h: off-screen, Nyquist, frames). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/config.h"
#include "studies/study_file.h"
#include "studies/study_plan.h"
#include "studies/study_run.h"
#include "stimuli/presenter.h"
#include "tests/check.h"

static const char *good_settings = "name = t\ndesign = 2afc\nconditions = c.csv\ntrials_per_condition = 10\n"
                                   "blocks = 2\n";

static csf_status settings(const char *text, csf_study *s, csf_error *e)
{
    memset(s, 0, sizeof *s);
    return csf_study_parse_settings(s, text, strlen(text), "s.conf", e);
}

/* Parses conditions for a study with the given settings; returns the status and the message. */
static csf_status conds(const char *set, const char *csv, csf_study *s, csf_error *e)
{
    csf_status st = settings(set, s, e);
    if (st != CSF_OK) return st;
    return csf_study_parse_conditions(s, csv, strlen(csv), "c.csv", "/tmp", e);
}

static void test_settings(void)
{
    csf_study s;
    csf_error e;
    CHECK(settings(good_settings, &s, &e) == CSF_OK);
    CHECK_INT_EQ(s.trials_per_condition, 10);
    CHECK(settings("name = t\nconditions = c.csv\nstimulus_s = 0\n", &s, &e) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "s.conf:3: stimulus_s = '0'");
    CHECK(settings("name = t\nconditions = c.csv\ntrials_per_condition = 10\nblocks = 3\n", &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "cannot be split into 3 equal blocks");
    CHECK(settings("name = t\ndesign = 2ifc\nconditions = c.csv\nisi_s = 0\n", &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "isi_s = 0");
    CHECK(settings("name = t\nconditions = c.csv\nresponse_window_s = 0.05\n", &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "nobody answers that fast");
    CHECK(settings("name = t\nconditions = c.csv\ndesign = yes_no\ncatch_fraction = 0\n", &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "catch trials");
    CHECK(settings("name = t\nconditions = c.csv\ndesign = 3afc\n", &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "s.conf:3: design = '3afc'");
    CHECK(settings("name = t\nconditions = c.csv\ntrails_per_condition = 4\n", &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "unknown key 'trails_per_condition'");
    CHECK(settings("name = t\n", &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "conditions");
    CHECK(settings("name = t\nconditions = c.csv\njust words\n", &s, &e) == CSF_E_FORMAT);
    CHECK_STR_CONTAINS(e.msg, "s.conf:3");
}

static void test_conditions(void)
{
    csf_study s;
    csf_error e;
    CHECK(conds(good_settings, "label,freq_cpd,contrast,ecc_deg\na,2,0.01,5\nb,4,adaptive,5\n", &s, &e) == CSF_OK);
    CHECK_INT_EQ(s.n_conds, 2);
    CHECK(s.conds[1].adaptive == 1);
    free(s.conds);
    /* missing column */
    CHECK(conds(good_settings, "label,freq_cpd,ecc_deg\na,2,5\n", &s, &e) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "c.csv:2 (a): gabor conditions need the columns freq_cpd and contrast");
    CHECK(conds(good_settings, "label,freq_cpd,contrast\na,2,0.1\n", &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "c.csv:1: missing column 'ecc_deg'");
    /* a column of the user's own is carried (a gabor still needs freq_cpd); a known column in
     * other letter case, one the export writes itself and a name that is no identifier are
     * refused; bad value, duplicate label, wrong field count */
    CHECK(conds(good_settings, "label,freq,contrast,ecc_deg\na,2,0.1,5\n", &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "c.csv:2 (a): gabor conditions need the columns freq_cpd and contrast");
    CHECK(conds(good_settings, "label,freq_cpd,contrast,ecc_deg,corrAns,my.note\na,2,0.1,5,left,x\n", &s,
                &e) == CSF_OK);
    free(s.conds);
    CHECK(conds(good_settings, "label,freq_cpd,Contrast,ecc_deg\na,2,0.1,5\n", &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "c.csv:1: column 'Contrast': did you mean 'contrast'?");
    CHECK(conds(good_settings, "label,freq_cpd,contrast,ecc_deg,rt_s\na,2,0.1,5,1\n", &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "column 'rt_s' is one the trial export writes itself");
    CHECK(conds(good_settings, "label,freq_cpd,contrast,ecc_deg,2nd\na,2,0.1,5,1\n", &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "column '2nd': a column of your own");
    CHECK(conds(good_settings, "label,freq_cpd,contrast,ecc_deg,x,x\na,2,0.1,5,1,2\n", &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "column 'x' appears twice");
    CHECK(conds(good_settings, "label,freq_cpd,contrast,ecc_deg\na,2,1.5,5\n", &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "c.csv:2 (a): contrast = '1.5'");
    CHECK(conds(good_settings, "label,freq_cpd,contrast,ecc_deg\na,2,0.1,5\n\na,3,0.1,5\n", &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "c.csv:4: label 'a' already used on line 2");
    CHECK(conds(good_settings, "label,freq_cpd,contrast,ecc_deg\na,2,0.1\n", &s, &e) == CSF_E_FORMAT);
    CHECK_STR_CONTAINS(e.msg, "c.csv:2: 3 fields, the header has 4");
    /* 2afc places that overlap at the fovea */
    CHECK(conds(good_settings, "label,freq_cpd,contrast,ecc_deg\na,2,0.1,1\n", &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "overlap");
    /* designs and stimuli that do not go together */
    const char *sd = "name = t\ndesign = same_different\nconditions = c.csv\n";
    CHECK(conds(sd, "label,freq_cpd,contrast,ecc_deg\na,2,0.1,5\n", &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "compares image pairs");
    const char *yn = "name = t\ndesign = yes_no\nconditions = c.csv\n";
    CHECK(conds(yn, "label,freq_cpd,contrast,ecc_deg\na,2,adaptive,5\n", &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "adaptive contrast needs a 2afc or 2ifc design");
    CHECK(conds(sd, "label,stimulus,image_a,ecc_deg,size_deg\na,image,x.png,0,4\n", &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "image_a, image_b and size_deg");
    /* quoted fields */
    CHECK(conds(good_settings, "label,freq_cpd,contrast,ecc_deg\n\"a b\",\"2\",0.1,5\n", &s, &e) == CSF_OK);
    CHECK(!strcmp(s.conds[0].label, "a b"));
    free(s.conds);
    CHECK(conds(good_settings, "label,freq_cpd,contrast,ecc_deg\n\"a,2,0.1,5\n", &s, &e) == CSF_E_FORMAT);
    CHECK(conds(good_settings, "label,freq_cpd,contrast,ecc_deg\n", &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "no conditions");
}

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (!f) return;
    fputs(text, f);
    fclose(f);
}

/* Missing image files are named with the conditions file's line, before anything runs. */
static void test_missing_image(const char *dir)
{
    char p[512], c[512];
    snprintf(p, sizeof p, "%s/sd.conf", dir);
    snprintf(c, sizeof c, "%s/sd.csv", dir);
    write_file(p, "name = sd\ndesign = same_different\nconditions = sd.csv\n");
    write_file(c, "label,stimulus,image_a,image_b,size_deg,ecc_deg\n# a comment\npair,image,no_such_a.png,b.png,4,0\n");
    csf_study *s = NULL;
    csf_error e;
    CHECK(csf_study_load(p, &s, &e) == CSF_E_NOT_FOUND);
    CHECK_STR_CONTAINS(e.msg, "sd.csv:3 (pair): image_a");
    CHECK_STR_CONTAINS(e.msg, "no_such_a.png");
    CHECK(s == NULL);
    /* a conditions file that is not there */
    write_file(p, "name = sd\ndesign = 2afc\nconditions = nothere.csv\n");
    CHECK(csf_study_load(p, &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "nothere.csv");
}

/* Display checks: off-screen, above the Nyquist limit, shorter than a frame. */
static void test_display(const char *dir)
{
    csf_config cfg;
    csf_config_defaults(&cfg);
    csf_presenter_config pc;
    csf_presenter_config_defaults(&pc);
    pc.headless = 1;
    csf_error e;
    CHECK(csf_geometry_init(&pc.geometry, CSF_GEOMETRY_FROM_CONFIG(cfg), &e) == CSF_OK);
    pc.render_width_px = 64;
    pc.render_height_px = 36;
    pc.render_every = -1;
    csf_presenter *pres = NULL;
    if (csf_presenter_open(&pc, &pres, &e) != CSF_OK) {
        fprintf(stderr, "presenter: %s\n", e.msg);
        CHECK(0);
        return;
    }
    char p[512], c[512];
    snprintf(p, sizeof p, "%s/d.conf", dir);
    snprintf(c, sizeof c, "%s/d.csv", dir);
    write_file(p, "name = d\ndesign = 2afc\nconditions = d.csv\ntrials_per_condition = 2\n");
    struct {
        const char *csv, *want;
    } cases[] = {
        {"label,freq_cpd,contrast,ecc_deg\nok,2,0.1,5\nfar,2,0.1,60\n", "d.csv:3 (far)"},
        {"label,freq_cpd,contrast,ecc_deg\nfine,60,0.1,5\n", "Nyquist"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        write_file(c, cases[i].csv);
        csf_study *s = NULL;
        CHECK(csf_study_load(p, &s, &e) == CSF_OK);
        if (!s) continue;
        CHECK(csf_study_check_display(s, pres, &e) == CSF_E_INVALID_ARG);
        CHECK_STR_CONTAINS(e.msg, cases[i].want);
        csf_study_free(s);
    }
    write_file(p, "name = d\ndesign = 2afc\nconditions = d.csv\ntrials_per_condition = 2\nstimulus_s = 0.005\n");
    write_file(c, "label,freq_cpd,contrast,ecc_deg\nok,2,0.1,5\n");
    csf_study *s = NULL;
    CHECK(csf_study_load(p, &s, &e) == CSF_OK);
    if (s) {
        CHECK(csf_study_check_display(s, pres, &e) == CSF_E_INVALID_ARG);
        CHECK_STR_CONTAINS(e.msg, "shorter than one frame");
        csf_study_free(s);
    }
    csf_presenter_close(pres);
}

/* The plan: every condition its trials, balanced targets, same order for the same seed. */
static void test_plan(void)
{
    csf_study s;
    csf_error e;
    CHECK(conds("name = t\nconditions = c.csv\ntrials_per_condition = 20\nblocks = 2\npractice_trials = 3\n",
                "label,freq_cpd,contrast,ecc_deg\na,2,0.01,5\nb,4,0.02,5\n", &s, &e) == CSF_OK);
    csf_study_trial *t1 = NULL, *t2 = NULL;
    int n1, n2;
    CHECK(csf_study_make_plan(&s, 5, 0, &t1, &n1, &e) == CSF_OK);
    CHECK(csf_study_make_plan(&s, 5, 0, &t2, &n2, &e) == CSF_OK);
    CHECK_INT_EQ(n1, 43);
    CHECK(n1 == n2 && !memcmp(t1, t2, (size_t)n1 * sizeof *t1));
    int per[2][2] = {{0, 0}, {0, 0}}, prac = 0;
    for (int i = 0; i < n1; i++) {
        if (t1[i].practice) {
            prac++;
            CHECK(i < 3);
            continue;
        }
        per[t1[i].cond][t1[i].target]++;
        if (i > 3) CHECK(t1[i].block >= t1[i - 1].block);
    }
    CHECK_INT_EQ(prac, 3);
    CHECK_INT_EQ(per[0][0], 10);
    CHECK_INT_EQ(per[0][1], 10);
    CHECK_INT_EQ(per[1][1], 10);
    free(t1);
    free(t2);
    free(s.conds);
}

/* What a new run is refused, each with its line and reason: a settings key given twice (the
 * last used to win silently), a catch fraction that the plan would round, a curve whose
 * conditions mix frequencies (fitted as one function with a slope of 0.5). A stored copy from
 * an older csfcal with a key given twice still reads back, so its sessions can be reported. */
static void test_new_run_rules(const char *dir)
{
    char p[512], c[512];
    snprintf(p, sizeof p, "%s/r.conf", dir);
    snprintf(c, sizeof c, "%s/r.csv", dir);
    csf_study *s = NULL;
    csf_error e;
    const char *csv = "label,freq_cpd,contrast,ecc_deg,curve\na1,2,0.01,5,a\na2,2,0.02,5,a\n";
    write_file(c, csv);
    write_file(p, "name = r\ndesign = 2afc\nconditions = r.csv\ntrials_per_condition = 10\n"
                  "trials_per_condition = 20\n");
    CHECK(csf_study_load(p, &s, &e) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "r.conf:5: trials_per_condition given twice (first on line 4)");
    CHECK(s == NULL);
    csf_study *old = NULL;
    CHECK(csf_study_from_texts("name = r\ndesign = 2afc\nconditions = r.csv\ntrials_per_condition = 10\n"
                               "trials_per_condition = 20\n", csv, p, c, 0, &old, &e) == CSF_OK);
    CHECK(old && old->trials_per_condition == 20);
    csf_study_free(old);

    write_file(p, "name = r\ndesign = yes_no\nconditions = r.csv\ntrials_per_condition = 10\n"
                  "catch_fraction = 0.25\n");
    CHECK(csf_study_load(p, &s, &e) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "catch_fraction = 0.25 of 10 trials per condition and block is 2.5 trials");
    write_file(p, "name = r\ndesign = yes_no\nconditions = r.csv\ntrials_per_condition = 12\n"
                  "catch_fraction = 0.25\n");
    CHECK_MSG(csf_study_load(p, &s, &e) == CSF_OK, "%s", e.msg);
    csf_study_free(s);
    s = NULL;

    write_file(c, "label,freq_cpd,contrast,ecc_deg,curve\na1,2,0.01,5,a\na2,4,0.02,5,a\n");
    write_file(p, "name = r\ndesign = 2afc\nconditions = r.csv\ntrials_per_condition = 10\n");
    CHECK(csf_study_load(p, &s, &e) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(e.msg, "r.csv:3 (a2): curve 'a' mixes 2 cpd at 5 deg (line 2) and 4 cpd at 5 deg");
    CHECK(s == NULL);
}

int main(void)
{
    char dir[] = "/tmp/csf_study_file_XXXXXX";
    if (!mkdtemp(dir)) return 1;
    test_settings();
    test_conditions();
    test_missing_image(dir);
    test_display(dir);
    test_plan();
    test_new_run_rules(dir);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", dir);
    return CHECK_RESULT();
}
