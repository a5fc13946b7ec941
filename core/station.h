/* What a station is: its screen (size in mm and pixels, refresh, depth), where the eye sits, and
 * which devices, store and display profile it uses. The procedures read it; cli/config.c fills
 * it from station.conf and the command line, the only place that does. */
#ifndef CSF_STATION_H
#define CSF_STATION_H

typedef struct {
    double screen_width_mm, screen_height_mm;
    int screen_width_px, screen_height_px;
    double viewing_distance_mm;
    double eye_offset_x_mm, eye_offset_y_mm; /* foot of the normal from the eye, relative to the screen centre */
    double refresh_hz;
    int framebuffer_bits;                    /* per channel: 8 or 10 */
    char monitor[128];                       /* index or name for GLFW; empty = primary */
    char photometer[256];                    /* device spec, e.g. "sim" or "sim:display=lcd" */
    char observer[256];                      /* "sim[:...]" or "human"; empty = human at a display, sim headless */
    char responder[128];                     /* "keyboard", "mouse", ... */
    char store_path[1024];                   /* empty = $XDG_DATA_HOME/csfcal/csfcal.sqlite */
    char display_profile[1024];              /* path of the display profile to use; empty = default display */
    double profile_max_age_days;             /* profiles older than this are flagged when used */
    char source[1024];                       /* file the values came from, or "(defaults)" */
} csf_config;

#endif
