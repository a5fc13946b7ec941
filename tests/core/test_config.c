#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/config.h"
#include "tests/check.h"

static const char *write_tmp(const char *text)
{
    static char path[64];
    snprintf(path, sizeof path, "/tmp/csfcal-test-config-XXXXXX");
    int fd = mkstemp(path);
    if (fd < 0) return NULL;
    FILE *f = fdopen(fd, "w");
    fputs(text, f);
    fclose(f);
    return path;
}

int main(void)
{
    csf_config c;
    csf_error err;
    csf_config_defaults(&c);
    CHECK_NEAR(c.viewing_distance_mm, 570.0, 0);

    const char *p = write_tmp("# station\n[station]\nscreen_width_mm = 600\nviewing_distance_mm=800 # comment\n"
                              "photometer = sim:display=lcd\n");
    CHECK(csf_config_load(&c, p, &err) == CSF_OK);
    CHECK_NEAR(c.screen_width_mm, 600, 0);
    CHECK_NEAR(c.viewing_distance_mm, 800, 0);
    CHECK_STR_CONTAINS(c.photometer, "sim:display=lcd");
    unlink(p);

    /* Out of range: file, line and the allowed range in the message. */
    csf_config_defaults(&c);
    p = write_tmp("screen_width_mm = 600\nviewing_distance_mm = 5\n");
    CHECK(csf_config_load(&c, p, &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, ":2:");
    CHECK_STR_CONTAINS(err.msg, "allowed 100 to 10000 mm");
    unlink(p);

    p = write_tmp("screen_width_px = 1280.5\n");
    CHECK(csf_config_load(&c, p, &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "whole number");
    unlink(p);

    p = write_tmp("refresh_hz = fast\n");
    CHECK(csf_config_load(&c, p, &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "not a number");
    unlink(p);

    p = write_tmp("no_such_key = 1\n");
    CHECK(csf_config_load(&c, p, &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "unknown key");
    unlink(p);

    p = write_tmp("just words\n");
    CHECK(csf_config_load(&c, p, &err) == CSF_E_FORMAT);
    unlink(p);

    p = write_tmp("framebuffer_bits = 9\n");
    CHECK(csf_config_load(&c, p, &err) == CSF_E_INVALID_ARG);
    unlink(p);

    /* A repeated key is refused, naming both lines (the second silently won before). */
    p = write_tmp("refresh_hz = 60\n\nrefresh_hz = 75\n");
    CHECK(csf_config_load(&c, p, &err) == CSF_E_FORMAT);
    CHECK_STR_CONTAINS(err.msg, ":3: refresh_hz is set twice (first on line 1)");
    unlink(p);

    /* A binary file is called that, not "a line longer than 2046 characters". */
    {
        char path[] = "/tmp/csfcal-test-config-XXXXXX";
        int fd = mkstemp(path);
        CHECK(fd >= 0);
        static const unsigned char bin[] = {'a', ' ', '=', ' ', '1', '\n', 0x7f, 'E', 'L', 'F', 0, 1, 2, 3};
        CHECK(write(fd, bin, sizeof bin) == (ssize_t)sizeof bin);
        close(fd);
        csf_config_defaults(&c);
        CHECK(csf_config_load(&c, path, &err) == CSF_E_FORMAT);
        CHECK_STR_CONTAINS(err.msg, ":2: not a text file");
        unlink(path);
    }
    /* A long text line still gets the length message. */
    {
        char *big = malloc(5000);
        CHECK(big != NULL);
        memset(big, 'x', 4998);
        big[4998] = '\n';
        big[4999] = '\0';
        p = write_tmp(big);
        free(big);
        CHECK(csf_config_load(&c, p, &err) == CSF_E_FORMAT);
        CHECK_STR_CONTAINS(err.msg, "line longer than 2046 characters");
        unlink(p);
    }

    /* A folder given as the configuration file is refused; it used to read as an empty file,
     * so every value silently stayed a default. */
    {
        char dir[] = "/tmp/csfcal-test-config-dir-XXXXXX";
        CHECK(mkdtemp(dir) != NULL);
        csf_config_defaults(&c);
        CHECK(csf_config_load(&c, dir, &err) != CSF_OK);
        CHECK_STR_CONTAINS(err.msg, "is a folder, not a file");
        rmdir(dir);
    }
    CHECK(csf_config_load(&c, "", &err) == CSF_E_INVALID_ARG);
    CHECK_STR_CONTAINS(err.msg, "--config: empty path");

    CHECK(csf_config_load(&c, "/nonexistent/csfcal.conf", &err) == CSF_E_IO);
    CHECK_STR_CONTAINS(err.msg, "/nonexistent/csfcal.conf");
    return CHECK_RESULT();
}
