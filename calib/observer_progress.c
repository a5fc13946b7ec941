/* The experimenter's progress line (see observer_progress.h). */
#include "calib/observer_progress.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

void obs_progress_init(obs_progress *p, int live)
{
    memset(p, 0, sizeof *p);
    p->live = live;
}

void obs_progress_event(obs_progress *p, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(p->last_event, sizeof p->last_event, fmt, ap);
    va_end(ap);
}

int obs_progress_trials_left(int n, double rms_log10, double target_log10, int cap)
{
    if (n < 10 || !(rms_log10 > 0) || !(target_log10 > 0) || !isfinite(rms_log10)) return -1;
    if (rms_log10 <= target_log10 || n >= cap) return 0;
    double need = n * (rms_log10 / target_log10) * (rms_log10 / target_log10);
    return need >= cap ? cap - n : (int)ceil(need) - n;
}

/* Minutes as "2.4 min", or "?" while unknown. */
static void minutes(char *buf, size_t len, double s)
{
    if (isfinite(s) && s >= 0) snprintf(buf, len, "%.1f min", s / 60.0);
    else snprintf(buf, len, "?");
}

void obs_progress_show(obs_progress *p, const obs_progress_state *s)
{
    if (!p->live) return;
    char head[96], spent[32], left[32];
    if (s->target > 0)
        snprintf(head, sizeof head, "trial %d (cap %d), predicted error %.3f of %.3f log10", s->trial,
                 s->budget, s->rms_log10, s->target);
    else snprintf(head, sizeof head, "trial %d of %d", s->trial, s->budget);
    minutes(spent, sizeof spent, s->spent_s);
    minutes(left, sizeof left, s->left_s);
    /* \r and erase-to-end-of-line: the line is redrawn where it stands */
    /* with a precision target the time left is an estimate from the error's fall so far */
    fprintf(stderr, "\r\033[Kcsfcal: %s | cells %d/%d at <= %.2f | %s so far, %s%s left%s%s", head,
            s->cells_settled, s->cells, s->settle_log10, spent, s->target > 0 ? "about " : "", left,
            p->last_event[0] ? " | last: " : "", p->last_event);
    fflush(stderr);
    p->on_screen = 1;
}

void obs_progress_end(obs_progress *p)
{
    if (!p->on_screen) return;
    fputc('\n', stderr);
    p->on_screen = 0;
}
