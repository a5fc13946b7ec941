/* Screen mirror: what csfcal writes (devices/screen_mirror.c) is what an emulator reads
 * (tests/emu/emu_screen.c); the simulator never writes it; a bad path is refused up front. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <dirent.h>

#include "devices/photometer.h"
#include "devices/screen_mirror.h"
#include "tests/check.h"
#include "tests/emu/emu_screen.h"

static int count_files(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    struct dirent *e;
    while (d && (e = readdir(d)))
        if (e->d_name[0] != '.') n++;
    if (d) closedir(d);
    return n;
}

int main(void)
{
    char dir[] = "/tmp/csf_mirror_XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char path[512];
    snprintf(path, sizeof path, "%s/screen", dir);
    csf_error err;
    csf_screen_mirror *m = NULL;

    unsetenv(CSF_SCREEN_MIRROR_ENV);
    CHECK(csf_screen_mirror_from_env(&m, &err) == CSF_OK && m == NULL);

    setenv(CSF_SCREEN_MIRROR_ENV, path, 1);
    CHECK(csf_screen_mirror_from_env(&m, &err) == CSF_OK && m != NULL);
    double rgb[3] = {0.25, 1.5, -0.1};
    CHECK(csf_screen_mirror_write(m, 41, rgb, 1, &err) == CSF_OK);
    emu_screen_patch p;
    char why[256];
    CHECK_MSG(emu_screen_read(NULL, &p, why, sizeof why) == 0, "%s", why);
    CHECK(p.seq == 41);
    CHECK_NEAR(p.drive[0], 0.25, 0);
    CHECK_NEAR(p.drive[1], 1.0, 0);  /* clamped */
    CHECK_NEAR(p.drive[2], 0.0, 0);
    CHECK(p.n_px == 1);
    /* rewritten in place, no temporary left beside it */
    double rgb2[3] = {0.5, 0.5, 0.5};
    CHECK(csf_screen_mirror_write(m, 42, rgb2, 64, &err) == CSF_OK);
    CHECK(emu_screen_read(path, &p, why, sizeof why) == 0 && p.seq == 42 && p.n_px == 64 && p.drive[1] == 0.5);
    CHECK(count_files(dir) == 1);
    csf_screen_mirror_free(m);

    /* the reader refuses what is not a mirror, and ignores lines it does not know */
    const char *bad[] = {"", "csfcal-screen-mirror 2\nseq 1\ndrive 0 0 0\n", "csfcal-screen-mirror 1\nseq 1\n",
                         "csfcal-screen-mirror 1\nseq 1\ndrive 0 2 0\n", "hello\n",
                         "csfcal-screen-mirror 1\nseq x\ndrive 0 0 0\n"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
        CHECK_MSG(emu_screen_parse(bad[i], strlen(bad[i]), &p, why, sizeof why) == -1, "case %zu", i);
    const char *later = "csfcal-screen-mirror 1\nseq 3\nfuture 1 2\ndrive 0.1 0.2 0.3\n";
    CHECK(emu_screen_parse(later, strlen(later), &p, why, sizeof why) == 0 && p.seq == 3 && p.drive[2] == 0.3);

    /* a path whose folder does not exist is refused before any reading, naming the variable */
    setenv(CSF_SCREEN_MIRROR_ENV, "/nonexistent-dir/screen", 1);
    CHECK(csf_screen_mirror_from_env(&m, &err) == CSF_E_IO && m == NULL);
    CHECK_MSG(strstr(err.msg, CSF_SCREEN_MIRROR_ENV) != NULL, "%s", err.msg);

    /* the simulator is told the patch directly and never writes the mirror */
    unlink(path);
    setenv(CSF_SCREEN_MIRROR_ENV, path, 1);
    csf_photometer *ph;
    CHECK(csf_photometer_open("sim:display=lcd", 1, &ph, &err) == CSF_OK);
    csf_photometer_show_patch(ph, 0.5, 0.5, 0.5);
    csf_photometer_reading r;
    CHECK(csf_photometer_measure(ph, &r, &err) == CSF_OK);
    csf_photometer_close(ph);
    struct stat sb;
    CHECK(stat(path, &sb) != 0);
    rmdir(dir);
    return CHECK_RESULT();
}
