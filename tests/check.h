/* Minimal assertion helpers for csfcal tests. A failed check prints file:line and the values,
 * counts the failure, and the test's main returns CHECK_RESULT() (non-zero if anything failed). */
#ifndef CSF_TESTS_CHECK_H
#define CSF_TESTS_CHECK_H

#include <math.h>
#include <stdio.h>
#include <string.h>

static int check_failures_ = 0;
static int check_count_ = 0;

#define CHECK(cond)                                                                    \
    do {                                                                               \
        check_count_++;                                                                \
        if (!(cond)) {                                                                 \
            check_failures_++;                                                         \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond);  \
        }                                                                              \
    } while (0)

#define CHECK_MSG(cond, ...)                                                           \
    do {                                                                               \
        check_count_++;                                                                \
        if (!(cond)) {                                                                 \
            check_failures_++;                                                         \
            fprintf(stderr, "%s:%d: CHECK failed: %s: ", __FILE__, __LINE__, #cond);  \
            fprintf(stderr, __VA_ARGS__);                                              \
            fputc('\n', stderr);                                                       \
        }                                                                              \
    } while (0)

#define CHECK_NEAR(a, b, tol)                                                          \
    do {                                                                               \
        double ca_ = (double)(a), cb_ = (double)(b), ct_ = (double)(tol);              \
        check_count_++;                                                                \
        if (!(fabs(ca_ - cb_) <= ct_)) {                                               \
            check_failures_++;                                                         \
            fprintf(stderr, "%s:%d: CHECK_NEAR failed: %s = %.9g, %s = %.9g, tol %.3g\n", \
                    __FILE__, __LINE__, #a, ca_, #b, cb_, ct_);                        \
        }                                                                              \
    } while (0)

#define CHECK_INT_EQ(a, b)                                                             \
    do {                                                                               \
        long long ca_ = (long long)(a), cb_ = (long long)(b);                          \
        check_count_++;                                                                \
        if (ca_ != cb_) {                                                              \
            check_failures_++;                                                         \
            fprintf(stderr, "%s:%d: CHECK_INT_EQ failed: %s = %lld, %s = %lld\n",     \
                    __FILE__, __LINE__, #a, ca_, #b, cb_);                             \
        }                                                                              \
    } while (0)

#define CHECK_STR_CONTAINS(hay, needle)                                                \
    do {                                                                               \
        const char *ch_ = (hay), *cn_ = (needle);                                      \
        check_count_++;                                                                \
        if (!ch_ || !strstr(ch_, cn_)) {                                               \
            check_failures_++;                                                         \
            fprintf(stderr, "%s:%d: expected \"%s\" in \"%s\"\n", __FILE__, __LINE__, \
                    cn_, ch_ ? ch_ : "(null)");                                        \
        }                                                                              \
    } while (0)

#define CHECK_RESULT()                                                                 \
    (fprintf(stderr, "%d checks, %d failed\n", check_count_, check_failures_),         \
     check_failures_ ? 1 : 0)

#endif
