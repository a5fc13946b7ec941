/* Study designs (docs/studies.md, "Designs"): condition order (random, sequential, blocked by a
 * column), Latin-square counterbalancing across participants (Williams 1949), practice from
 * named conditions, feedback on practice only, instructions (text, or a file that joins the
 * study's identity), and the refusals of combinations that would not do what they say. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "studies/study_file.h"
#include "studies/study_identity.h"
#include "studies/study_plan.h"
#include "tests/check.h"

/* A study from settings and conditions texts (no files); the status, message in e. */
static csf_status study(const char *set, const char *csv, csf_study **s, csf_error *e)
{
    return csf_study_from_texts(set, csv, "s.conf", "c.csv", 0, s, e);
}

static const char *four = "label,grp,freq_cpd,contrast,ecc_deg\n"
                          "a,x,2,0.01,5\nb,y,2,0.02,5\nc,x,4,0.01,5\nd,y,4,0.02,5\n";

/* Williams rows: each item once per row and once per position over the rows; every ordered
 * pair of neighbours once (even n, n rows) or twice (odd n, 2n rows). */
static void test_williams(void)
{
    for (int n = 2; n <= 9; n++) {
        int rows = n % 2 ? 2 * n : n;
        int pos[9][9] = {{0}}, pair[9][9] = {{0}};
        for (int r = 0; r < rows; r++) {
            int row[9], seen[9] = {0};
            csf_study_williams_row(n, r, row);
            for (int j = 0; j < n; j++) {
                CHECK(row[j] >= 0 && row[j] < n);
                seen[row[j]]++;
                pos[row[j]][j]++;
                if (j) pair[row[j - 1]][row[j]]++;
            }
            for (int i = 0; i < n; i++) CHECK_INT_EQ(seen[i], 1);
        }
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) {
                CHECK_INT_EQ(pos[i][j], rows / n);
                if (i != j)
                    CHECK_MSG(pair[i][j] == rows / n, "n %d: pair %d->%d %d times", n, i, j, pair[i][j]);
            }
        int a[9], b[9];
        csf_study_williams_row(n, 1, a);
        csf_study_williams_row(n, 1 + rows, b);
        CHECK(!memcmp(a, b, (size_t)n * sizeof a[0])); /* rows repeat after the square */
    }
}

/* The main trials' conditions in plan order. */
static int mains(const csf_study_trial *t, int n, int *out)
{
    int k = 0;
    for (int i = 0; i < n; i++)
        if (!t[i].practice) out[k++] = t[i].cond;
    return k;
}

static void test_sequential(void)
{
    csf_study *s = NULL;
    csf_error e;
    CHECK_MSG(study("name = t\nconditions = c.csv\ntrials_per_condition = 3\norder = sequential\n"
                    "practice_trials = 0\n",
                    four, &s, &e) == CSF_OK,
              "%s", e.msg);
    csf_study_trial *t = NULL;
    int n = 0, c[64] = {0};
    CHECK(csf_study_make_plan(s, 9, 0, &t, &n, &e) == CSF_OK);
    CHECK_INT_EQ(mains(t, n, c), 12);
    for (int i = 0; i < 12; i++) CHECK_MSG(c[i] == i % 4, "trial %d: condition %d", i, c[i]);
    free(t);
    csf_study_free(s);

    /* latin_conditions: each participant's passes follow their Williams row */
    CHECK_MSG(study("name = t\nconditions = c.csv\ntrials_per_condition = 2\norder = sequential\n"
                    "counterbalance = latin_conditions\npractice_trials = 0\n",
                    four, &s, &e) == CSF_OK,
              "%s", e.msg);
    for (int p = 0; p < 5; p++) {
        int row[4];
        csf_study_williams_row(4, p, row);
        CHECK(csf_study_make_plan(s, 9, p, &t, &n, &e) == CSF_OK);
        CHECK_INT_EQ(mains(t, n, c), 8);
        for (int i = 0; i < 8; i++) CHECK_INT_EQ(c[i], row[i % 4]);
        CHECK_INT_EQ(csf_study_latin_row(s, p, NULL), p % 4);
        free(t);
    }
    csf_study_free(s);
}

static void test_blocked(void)
{
    csf_study *s = NULL;
    csf_error e;
    CHECK_MSG(study("name = t\nconditions = c.csv\ntrials_per_condition = 6\nblocked_by = grp\n"
                    "counterbalance = latin_blocks\npractice_trials = 2\n",
                    four, &s, &e) == CSF_OK,
              "%s", e.msg);
    CHECK_INT_EQ(s->n_groups, 2);
    CHECK(s->conds[0].group == 0 && s->conds[1].group == 1 && s->conds[2].group == 0 &&
          s->conds[3].group == 1);
    const char *first_grp[2] = {"x", "y"};
    for (int p = 0; p < 2; p++) {
        csf_study_trial *t = NULL;
        int n = 0;
        CHECK(csf_study_make_plan(s, 11, p, &t, &n, &e) == CSF_OK);
        CHECK_INT_EQ(n, 2 + 24);
        /* block 0 holds only the conditions of the participant's first value, all 6 trials each */
        int per[4] = {0};
        for (int i = 2; i < n; i++) {
            int g = s->conds[t[i].cond].group;
            CHECK_INT_EQ(t[i].block, i < 14 ? 0 : 1);
            CHECK_MSG(g == (i < 14 ? p : 1 - p), "participant %d trial %d: group %d", p, i, g);
            per[t[i].cond]++;
        }
        for (int k = 0; k < 4; k++) CHECK_INT_EQ(per[k], 6);
        CHECK(!strcmp(first_grp[s->conds[t[2].cond].group], p ? "y" : "x"));
        free(t);
    }
    csf_study_free(s);
}

/* The combinations refused, each naming the key and why. */
static void test_refusals(void)
{
    csf_study *s = NULL;
    csf_error e;
    CHECK(study("name = t\nconditions = c.csv\ncounterbalance = latin_blocks\n", four, &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "latin_blocks orders blocks that differ: it needs blocked_by");
    CHECK(study("name = t\nconditions = c.csv\ncounterbalance = latin_conditions\n", four, &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "latin_conditions orders the conditions: it needs order = sequential");
    CHECK(study("name = t\nconditions = c.csv\nblocked_by = grp\nblocks = 2\n", four, &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "blocks = 2 cannot be given with it");
    CHECK(study("name = t\nconditions = c.csv\nblocked_by = group\n", four, &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "blocked_by = group: c.csv has no column of that name");
    CHECK(study("name = t\nconditions = c.csv\norder = blocked\n", four, &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "s.conf:3: order = 'blocked': expected random or sequential");
    CHECK(study("name = t\nconditions = c.csv\ncounterbalance = latin\n", four, &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "s.conf:3: counterbalance = 'latin': expected yes, no, none, latin_blocks");
    CHECK(study("name = t\nconditions = c.csv\nfeedback = sometimes\n", four, &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "s.conf:3: feedback = 'sometimes': expected none, practice or all");
    CHECK(study("name = t\nconditions = c.csv\n\npractice_conditions = a, zz\n", four, &s, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "s.conf:4: practice_conditions: no condition of c.csv is labelled 'zz'");
    CHECK(s == NULL);
}

/* Keys that keep their old meaning, and the new values beside them. */
static void test_values(void)
{
    static const struct {
        const char *line;
        int counterbalance, latin, feedback;
    } v[] = {
        {"counterbalance = yes", 1, CSF_LATIN_NONE, CSF_FEEDBACK_NONE},
        {"counterbalance = no", 0, CSF_LATIN_NONE, CSF_FEEDBACK_NONE},
        {"counterbalance = none", 0, CSF_LATIN_NONE, CSF_FEEDBACK_NONE},
        {"feedback = yes", 1, CSF_LATIN_NONE, CSF_FEEDBACK_ALL},
        {"feedback = no", 1, CSF_LATIN_NONE, CSF_FEEDBACK_NONE},
        {"feedback = practice", 1, CSF_LATIN_NONE, CSF_FEEDBACK_PRACTICE},
        {"feedback = all", 1, CSF_LATIN_NONE, CSF_FEEDBACK_ALL},
    };
    for (size_t i = 0; i < sizeof v / sizeof v[0]; i++) {
        char set[200];
        snprintf(set, sizeof set, "name = t\nconditions = c.csv\n%s\n", v[i].line);
        csf_study *s = NULL;
        csf_error e;
        CHECK_MSG(study(set, four, &s, &e) == CSF_OK, "%s: %s", v[i].line, e.msg);
        if (!s) continue;
        CHECK_MSG(s->counterbalance == v[i].counterbalance && (int)s->latin == v[i].latin &&
                      (int)s->feedback == v[i].feedback,
                  "%s", v[i].line);
        csf_study_free(s);
    }
    csf_study *s = NULL;
    csf_error e;
    CHECK(study("name = t\nconditions = c.csv\ninstructions = Look here.\\nThen press.\n", four, &s, &e) ==
          CSF_OK);
    CHECK(s && !strcmp(s->instructions, "Look here.\nThen press."));
    csf_study_free(s);
}

/* Practice draws only the named conditions. */
static void test_practice(void)
{
    csf_study *s = NULL;
    csf_error e;
    CHECK(study("name = t\nconditions = c.csv\npractice_trials = 40\npractice_conditions = b, d\n", four, &s,
                &e) == CSF_OK);
    csf_study_trial *t = NULL;
    int n = 0, drawn[4] = {0};
    CHECK(csf_study_make_plan(s, 3, 0, &t, &n, &e) == CSF_OK);
    for (int i = 0; i < n; i++)
        if (t[i].practice) drawn[t[i].cond]++;
    CHECK(drawn[0] == 0 && drawn[2] == 0 && drawn[1] > 0 && drawn[3] > 0 && drawn[1] + drawn[3] == 40);
    free(t);
    csf_study_free(s);
}

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f) return;
    fputs(text, f);
    fclose(f);
}

/* An instructions file is part of the study: changing it changes the identity, named. */
static void test_instructions_identity(const char *dir)
{
    char p[512], c[512], i[512];
    snprintf(p, sizeof p, "%s/s.conf", dir);
    snprintf(c, sizeof c, "%s/c.csv", dir);
    snprintf(i, sizeof i, "%s/read.txt", dir);
    write_file(c, four);
    write_file(p, "name = t\nconditions = c.csv\ninstructions_file = read.txt\n");
    write_file(i, "Fixate.\nAnswer left or right.\n");
    csf_study *s1 = NULL, *s2 = NULL;
    csf_error e;
    CHECK_MSG(csf_study_load(p, &s1, &e) == CSF_OK, "%s", e.msg);
    write_file(i, "Fixate the mark.\nAnswer left or right.\n");
    CHECK_MSG(csf_study_load(p, &s2, &e) == CSF_OK, "%s", e.msg);
    if (s1 && s2) {
        CHECK(s1->instructions_text && !strcmp(s1->instructions_text, "Fixate.\nAnswer left or right.\n"));
        CHECK(s1->hash != s2->hash);
        csf_study_identity a, b;
        CHECK(csf_study_identity_compute(s1, 0, &a, &e) == CSF_OK);
        CHECK(csf_study_identity_compute(s2, 0, &b, &e) == CSF_OK);
        CHECK(strcmp(a.sha256, b.sha256) != 0);
        CHECK(!strcmp(a.settings_sha256, b.settings_sha256) &&
              !strcmp(a.conditions_sha256, b.conditions_sha256));
        char what[500];
        CHECK_INT_EQ(csf_study_identity_diff(&a, &b, what, sizeof what), 1);
        CHECK_STR_CONTAINS(what, "the instructions file changed");
        /* the identity read back from a session's JSON keeps the instructions' hash */
        json_t *j = csf_study_identity_to_json(&a);
        csf_study_identity back;
        CHECK(csf_study_identity_from_json(j, &back, &e) == CSF_OK);
        CHECK(!strcmp(back.instructions_sha256, a.instructions_sha256) && !strcmp(back.sha256, a.sha256));
        json_decref(j);
        csf_study_identity_free(&back);
        csf_study_identity_free(&a);
        csf_study_identity_free(&b);
    }
    csf_study_free(s1);
    csf_study_free(s2);
    write_file(i, "Press \033[31m now\n");
    CHECK(csf_study_load(p, &s1, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "read.txt:1");
    remove(i);
    CHECK(csf_study_load(p, &s1, &e) != CSF_OK);
    CHECK_STR_CONTAINS(e.msg, "instructions_file = read.txt");
    remove(p);
    remove(c);
}

int main(void)
{
    char dir[] = "/tmp/csf_study_designs_XXXXXX";
    if (!mkdtemp(dir)) return 1;
    test_williams();
    test_sequential();
    test_blocked();
    test_refusals();
    test_values();
    test_practice();
    test_instructions_identity(dir);
    rmdir(dir);
    return CHECK_RESULT();
}
