#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "calib/config.h"
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
    CHECK_STR_CONTAINS(err.msg, "allowed 100 to 20000 mm");
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

    CHECK(csf_config_load(&c, "/nonexistent/csfcal.conf", &err) == CSF_E_IO);
    CHECK_STR_CONTAINS(err.msg, "/nonexistent/csfcal.conf");
    return CHECK_RESULT();
}
