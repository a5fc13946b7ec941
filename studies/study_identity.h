/* A study's identity (docs/studies.md, "Versions"): the content of everything a participant was
 * shown or run by: the settings file, the conditions file and every image they name. Each is
 * hashed with SHA-256 (OpenSSL libcrypto), and the identity is the SHA-256 of a manifest that
 * lists those hashes ("settings HEX", "conditions HEX", "instructions HEX" when the settings name
 * an instructions file, then "image HEX NAME" per image in the order the conditions first name
 * them), so two runs share an identity exactly when every byte
 * they used is the same, and a difference can be named (settings, conditions, which image).
 *
 * Every study session keeps its identity in its settings JSON (key "identity", with "version"
 * and "sha256" beside it) and every image in the store as an artifact of kind "image" (path: the
 * name as the conditions file writes it; bytes: the file), so the pictures a study used can be
 * recovered from the store alone and checked against their hashes. */
#ifndef CSF_STUDY_IDENTITY_H
#define CSF_STUDY_IDENTITY_H

#include <stddef.h>

#include <jansson.h>

#include "core/csf_status.h"
#include "studies/study_file.h"

#define CSF_SHA256_HEX 65 /* 64 hex digits and the NUL */
#define CSF_STUDY_IMAGE_MAX_BYTES (256u << 20)

typedef struct {
    char name[1024]; /* as the conditions file writes it (relative to its folder) */
    char path[1024]; /* resolved on this machine ("" for a stored identity) */
    char sha256[CSF_SHA256_HEX];
    unsigned char *bytes; /* the file, when kept (csf_study_identity_compute keep_bytes) */
    size_t len;
} csf_study_image;

typedef struct {
    char sha256[CSF_SHA256_HEX]; /* the manifest's: the study's identity */
    char settings_sha256[CSF_SHA256_HEX];
    char conditions_sha256[CSF_SHA256_HEX];
    char instructions_sha256[CSF_SHA256_HEX]; /* the instructions file's; "" without one */
    csf_study_image *images;                  /* malloc'd */
    int n_images;
} csf_study_identity;

/* An image's name as the conditions file wrote it: its resolved path less the conditions file's
 * folder. */
void csf_study_image_name(const csf_study *s, const char *path, char *out, size_t cap);

/* SHA-256 of len bytes as 64 lower-case hex digits. */
void csf_sha256_hex(const void *data, size_t len, char out[CSF_SHA256_HEX]);

/* The identity of a loaded study (csf_study_load: its texts are set, its images exist): reads
 * every image (at most CSF_STUDY_IMAGE_MAX_BYTES each); keep_bytes = 1 keeps their bytes to be
 * stored. CSF_E_NOT_FOUND naming the conditions line when an image cannot be read. */
csf_status csf_study_identity_compute(const csf_study *s, int keep_bytes, csf_study_identity *id,
                                      csf_error *err);
void csf_study_identity_free(csf_study_identity *id);

/* As JSON (new reference) for a session's settings: sha256, settings_sha256, conditions_sha256,
 * instructions_sha256 (only with an instructions file), images [{name, sha256, bytes}]. */
json_t *csf_study_identity_to_json(const csf_study_identity *id);
/* From that JSON (outside input: every hash must be 64 hex digits, names printable text);
 * CSF_E_FORMAT naming what is wrong. */
csf_status csf_study_identity_from_json(const json_t *j, csf_study_identity *id, csf_error *err);

/* What differs from the stored identity was to the present one, as a phrase for a message:
 * "the settings file changed; image blob.png changed; image new.png was added". Empty (and
 * returns 0) when they are the same; else returns the number of differences. */
int csf_study_identity_diff(const csf_study_identity *was, const csf_study_identity *now, char *out,
                            size_t cap);

#endif
