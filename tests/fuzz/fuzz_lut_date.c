/* `csfcal lut import --date` is outside input written into the table's metadata: a real UTC date
 * and time as YYYY-MM-DDTHH:MM:SSZ must be accepted and stored as given, anything else refused
 * with exit 2 and no table written. The input is the --date value; the oracle is an independent
 * check through timegm/gmtime (a date that does not survive the round trip is not a real date;
 * second 60 is allowed for leap seconds). */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "cli/commands.h"
#include "results/csflut/csflut.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static const char grid_csv[] = "freq_cpd,ecc_deg,threshold\n1,0,0.01\n4,0,0.004\n1,10,0.03\n4,10,0.05\n";

static int real_utc(const char *s)
{
    static const char form[] = "dddd-dd-ddTdd:dd:ddZ";
    if (strlen(s) != sizeof form - 1) return 0;
    for (size_t i = 0; form[i]; i++) {
        int digit = s[i] >= '0' && s[i] <= '9';
        if (form[i] == 'd' ? !digit : s[i] != form[i]) return 0;
    }
    int f[6];
    const int pos[6] = {0, 5, 8, 11, 14, 17}, len[6] = {4, 2, 2, 2, 2, 2};
    for (int k = 0; k < 6; k++) {
        f[k] = 0;
        for (int i = 0; i < len[k]; i++) f[k] = f[k] * 10 + (s[pos[k] + i] - '0');
    }
    if (f[0] < 1 || f[5] > 60) return 0;
    struct tm tm = {.tm_year = f[0] - 1900, .tm_mon = f[1] - 1, .tm_mday = f[2], .tm_hour = f[3],
                    .tm_min = f[4], .tm_sec = f[5] == 60 ? 59 : f[5]};
    time_t t = timegm(&tm);
    struct tm back;
    if (!gmtime_r(&t, &back)) return 0;
    return back.tm_year == f[0] - 1900 && back.tm_mon == f[1] - 1 && back.tm_mday == f[2] &&
           back.tm_hour == f[3] && back.tm_min == f[4];
}

static char dir[] = "/tmp/csfcal-fuzz-date-XXXXXX";
static char csv[64], out[64];

static void cleanup(void)
{
    unlink(out);
    unlink(csv);
    rmdir(dir);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!csv[0]) {
        if (!mkdtemp(dir)) abort();
        atexit(cleanup);
        snprintf(csv, sizeof csv, "%s/grid.csv", dir);
        snprintf(out, sizeof out, "%s/out.csflut", dir);
        FILE *f = fopen(csv, "w");
        if (!f || fputs(grid_csv, f) < 0 || fclose(f) != 0) abort();
    }
    if (size > 200) return 0;
    char date[201];
    memcpy(date, data, size);
    date[size] = '\0';
    char *argv[] = {"lut", "import", csv, "-o", out, "--date", date, NULL};
    unlink(out);
    int rc = csf_cmd_lut(7, argv);
    int real = real_utc(date);
    if (real) {
        csflut_table *t = NULL;
        if (rc != 0 || csflut_open_file(out, &t) != CSFLUT_OK) abort(); /* a real date is refused */
        const char *stored = csflut_date_utc(t);
        if (!stored || strcmp(stored, date) != 0) abort(); /* stored as given */
        csflut_close(t);
    } else {
        if (rc != 2 || access(out, F_OK) == 0) abort(); /* not a date, yet accepted */
    }
    unlink(out);
    return 0;
}
