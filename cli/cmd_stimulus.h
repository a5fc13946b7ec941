/* What the `csfcal stimulus` subcommands share: their options, the luminance truth a rendered
 * frame is measured against, and the stimulus they build from the options (internal to
 * cli/cmd_stimulus*.c). */
#ifndef CSF_CLI_CMD_STIMULUS_H
#define CSF_CLI_CMD_STIMULUS_H

#include "cli/cli.h"
#include "model/display_model.h"
#include "results/display_profile.h"
#include "stimuli/presenter.h"
#include "stimuli/selfcheck.h"

#define STIM_MAX_DROPS 16

/* What `stimulus check`, `show` and `geometry` were asked for. NAN / 0 = not given. */
typedef struct {
    double freq_cpd, ecc_deg, polar_deg, contrast, orientation_deg, sigma_deg, mean_lum_cdm2;
    double velocity_dps; /* carrier drift speed; the temporal frequency is velocity x freq */
    double miss_rate;
    long frames, levels, bits, quit_after_frames;
    long drop_frames[STIM_MAX_DROPS];
    int n_drops;
    int grating, frames_set, windowed, clean, no_fixation;
    const char *png;  /* show: a PNG file, or a folder ending in '/' for --frames */
    const char *keys; /* show: scripted key presses, one per frame */
} stim_args;

/* The options into a (and the station's settings into cli). Returns -1 to go on, or the exit
 * status: 0 after --help, 2 for a bad option. */
int stim_parse_options(int argc, char **argv, const char *sub, csf_cli *cli, stim_args *a);

/* The luminance a rendered frame is measured against: a simulated display's exact curves, a
 * measured profile, or the default display model. */
typedef struct {
    csf_display_model *model;
    csf_display_profile *profile, *deflt;
    csf_pixel_lum_fn lum;
    void *lum_ctx;
    char truth[700];
} stim_truth;

/* Opens the truth and tells the presenter what it maps luminance through. Returns -1 to go on,
 * or the exit status (the message printed, naming `cmd`). */
int stim_open_truth(const csf_cli *cli, const char *cmd, csf_presenter_config *pc, stim_truth *t);
void stim_close_truth(stim_truth *t);

/* The stimulus the options describe (a session's Gabor, or a grating of radius 3 sigma), drifting
 * at velocity x freq. */
void stim_from_args(const stim_args *a, csf_stimulus *s);

/* 0 when |velocity| x freq is below half of refresh_hz; else prints why (naming `cmd`, the
 * temporal frequency and the highest velocity allowed at that frequency) into msg and returns -1. */
int stim_check_aliasing(const stim_args *a, double refresh_hz, char *msg, size_t len);

int csf_cmd_stimulus_show(csf_cli *cli, const stim_args *a);

#endif
