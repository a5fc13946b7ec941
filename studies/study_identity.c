/* A study's identity (see study_identity.h). */
#include "studies/study_identity.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <openssl/evp.h>

#include "core/file_read.h"
#include "results/store/store.h"

void csf_sha256_hex(const void *data, size_t len, char out[CSF_SHA256_HEX])
{
    unsigned char md[EVP_MAX_MD_SIZE];
    unsigned int n = 0;
    out[0] = '\0';
    if (!EVP_Digest(data, len, md, &n, EVP_sha256(), NULL) || n != 32) return;
    for (unsigned int i = 0; i < n; i++) snprintf(out + 2 * i, 3, "%02x", md[i]);
}

void csf_study_identity_free(csf_study_identity *id)
{
    if (!id) return;
    for (int i = 0; i < id->n_images; i++) free(id->images[i].bytes);
    free(id->images);
    memset(id, 0, sizeof *id);
}

/* The manifest's hash: the identity (see the header for its lines). */
static csf_status seal(csf_study_identity *id, csf_error *err)
{
    size_t cap = 256 + (size_t)id->n_images * (CSF_SHA256_HEX + 1040), n = 0;
    char *m = malloc(cap);
    if (!m) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    n += (size_t)snprintf(m + n, cap - n, "settings %s\nconditions %s\n", id->settings_sha256,
                          id->conditions_sha256);
    if (id->instructions_sha256[0])
        n += (size_t)snprintf(m + n, cap - n, "instructions %s\n", id->instructions_sha256);
    for (int i = 0; i < id->n_images; i++)
        n += (size_t)snprintf(m + n, cap - n, "image %s %s\n", id->images[i].sha256, id->images[i].name);
    csf_sha256_hex(m, n, id->sha256);
    free(m);
    return CSF_OK;
}

/* The name of an image as the conditions file wrote it: its resolved path less the conditions
 * file's folder (csf_study_load resolves names against that folder). */
void csf_study_image_name(const csf_study *s, const char *path, char *out, size_t cap)
{
    const char *slash = strrchr(s->conditions_path, '/');
    size_t dn = slash ? (size_t)(slash - s->conditions_path) : 0;
    if (slash && !strncmp(path, s->conditions_path, dn) && path[dn] == '/')
        snprintf(out, cap, "%s", path + dn + 1);
    else if (!slash && strncmp(path, "./", 2) == 0) snprintf(out, cap, "%s", path + 2);
    else snprintf(out, cap, "%s", path);
}

static csf_status add_image(csf_study_identity *id, const csf_study *s, const csf_study_condition *c,
                            const char *path, const char *col, int keep, csf_error *err)
{
    for (int i = 0; i < id->n_images; i++)
        if (!strcmp(id->images[i].path, path)) return CSF_OK;
    char *bytes = NULL;
    size_t len = 0;
    csf_error e;
    if (csf_read_file(path, "study image", CSF_STUDY_IMAGE_MAX_BYTES, &bytes, &len, &e) != CSF_OK)
        return csf_error_set(err, CSF_E_NOT_FOUND, "%s:%d (%s): %s: %s", s->conditions_path, c->line,
                             c->label, col, e.msg);
    csf_study_image *im = &id->images[id->n_images++];
    snprintf(im->path, sizeof im->path, "%s", path);
    csf_study_image_name(s, path, im->name, sizeof im->name);
    csf_sha256_hex(bytes, len, im->sha256);
    im->len = len;
    if (keep) im->bytes = (unsigned char *)bytes;
    else free(bytes);
    return CSF_OK;
}

csf_status csf_study_identity_compute(const csf_study *s, int keep_bytes, csf_study_identity *id,
                                      csf_error *err)
{
    memset(id, 0, sizeof *id);
    csf_sha256_hex(s->settings_text, strlen(s->settings_text), id->settings_sha256);
    csf_sha256_hex(s->conditions_text, strlen(s->conditions_text), id->conditions_sha256);
    if (s->instructions_text)
        csf_sha256_hex(s->instructions_text, strlen(s->instructions_text), id->instructions_sha256);
    id->images = calloc(2 * (size_t)s->n_conds + 1, sizeof *id->images);
    if (!id->images) return csf_error_set(err, CSF_E_NOMEM, "out of memory");
    csf_status st = CSF_OK;
    for (int i = 0; st == CSF_OK && i < s->n_conds; i++) {
        const csf_study_condition *c = &s->conds[i];
        if (c->kind != CSF_COND_IMAGE) continue;
        st = add_image(id, s, c, c->image_a, "image_a", keep_bytes, err);
        if (st == CSF_OK) st = add_image(id, s, c, c->image_b, "image_b", keep_bytes, err);
    }
    if (st == CSF_OK) st = seal(id, err);
    if (st != CSF_OK) csf_study_identity_free(id);
    return st;
}

json_t *csf_study_identity_to_json(const csf_study_identity *id)
{
    json_t *imgs = json_array();
    for (int i = 0; imgs && i < id->n_images; i++)
        json_array_append_new(imgs, json_pack("{s:s,s:s,s:I}", "name", id->images[i].name, "sha256",
                                              id->images[i].sha256, "bytes", (json_int_t)id->images[i].len));
    json_t *j = json_pack("{s:s,s:s,s:s}", "sha256", id->sha256, "settings_sha256", id->settings_sha256,
                          "conditions_sha256", id->conditions_sha256);
    if (j && id->instructions_sha256[0])
        json_object_set_new(j, "instructions_sha256", json_string(id->instructions_sha256));
    if (j) json_object_set_new(j, "images", imgs);
    else json_decref(imgs);
    return j;
}

static int is_hex64(const char *h)
{
    if (!h || strlen(h) != 64) return 0;
    for (const char *p = h; *p; p++)
        if (!((*p >= '0' && *p <= '9') || (*p >= 'a' && *p <= 'f'))) return 0;
    return 1;
}

static csf_status get_hash(const json_t *j, const char *key, char out[CSF_SHA256_HEX], csf_error *err)
{
    const char *v = json_string_value(json_object_get(j, key));
    if (!is_hex64(v))
        return csf_error_set(err, CSF_E_FORMAT, "study identity: %s is not 64 lower-case hex digits", key);
    memcpy(out, v, CSF_SHA256_HEX);
    return CSF_OK;
}

csf_status csf_study_identity_from_json(const json_t *j, csf_study_identity *id, csf_error *err)
{
    memset(id, 0, sizeof *id);
    if (!json_is_object(j)) return csf_error_set(err, CSF_E_FORMAT, "study identity: not a JSON object");
    csf_status st = get_hash(j, "sha256", id->sha256, err);
    if (st == CSF_OK) st = get_hash(j, "settings_sha256", id->settings_sha256, err);
    if (st == CSF_OK) st = get_hash(j, "conditions_sha256", id->conditions_sha256, err);
    if (st == CSF_OK && json_object_get(j, "instructions_sha256"))
        st = get_hash(j, "instructions_sha256", id->instructions_sha256, err);
    const json_t *imgs = json_object_get(j, "images");
    if (st == CSF_OK && (!json_is_array(imgs) || json_array_size(imgs) > 2 * CSF_STUDY_MAX_CONDITIONS))
        st = csf_error_set(err, CSF_E_FORMAT, "study identity: images is not a list of at most %d",
                           2 * CSF_STUDY_MAX_CONDITIONS);
    if (st == CSF_OK && !(id->images = calloc(json_array_size(imgs) + 1, sizeof *id->images)))
        st = csf_error_set(err, CSF_E_NOMEM, "out of memory");
    for (size_t i = 0; st == CSF_OK && i < json_array_size(imgs); i++) {
        const json_t *e = json_array_get(imgs, i);
        csf_study_image *im = &id->images[id->n_images];
        const char *name = json_string_value(json_object_get(e, "name"));
        if (!name || !*name || strlen(name) >= sizeof im->name ||
            csf_store_check_text(name, "study identity: image name", err) != CSF_OK) {
            st = csf_error_set(err, CSF_E_FORMAT, "study identity: image %zu has no printable name", i + 1);
            break;
        }
        snprintf(im->name, sizeof im->name, "%s", name);
        if ((st = get_hash(e, "sha256", im->sha256, err)) != CSF_OK) break;
        json_int_t bytes = json_integer_value(json_object_get(e, "bytes"));
        im->len = bytes > 0 ? (size_t)bytes : 0;
        id->n_images++;
    }
    if (st != CSF_OK) csf_study_identity_free(id);
    return st;
}

/* Appends one difference to the phrase ("; " between them). */
static void say(char *out, size_t cap, int *n, const char *what)
{
    size_t used = strlen(out);
    if (used + 1 < cap) snprintf(out + used, cap - used, "%s%s", (*n)++ ? "; " : "", what);
}

static const csf_study_image *find_image(const csf_study_identity *id, const char *name)
{
    for (int i = 0; i < id->n_images; i++)
        if (!strcmp(id->images[i].name, name)) return &id->images[i];
    return NULL;
}

int csf_study_identity_diff(const csf_study_identity *was, const csf_study_identity *now, char *out,
                            size_t cap)
{
    int n = 0;
    char m[1200];
    out[0] = '\0';
    if (!strcmp(was->sha256, now->sha256)) return 0;
    if (strcmp(was->settings_sha256, now->settings_sha256)) say(out, cap, &n, "the settings file changed");
    if (strcmp(was->conditions_sha256, now->conditions_sha256))
        say(out, cap, &n, "the conditions file changed");
    if (strcmp(was->instructions_sha256, now->instructions_sha256))
        say(out, cap, &n,
            !was->instructions_sha256[0]   ? "an instructions file was added"
            : !now->instructions_sha256[0] ? "the instructions file is no longer used"
                                           : "the instructions file changed");
    for (int i = 0; i < now->n_images; i++) {
        const csf_study_image *w = find_image(was, now->images[i].name);
        if (!w) snprintf(m, sizeof m, "image %s was added", now->images[i].name);
        else if (strcmp(w->sha256, now->images[i].sha256))
            snprintf(m, sizeof m, "image %s changed (SHA-256 was %.12s..., now %.12s...)",
                     now->images[i].name, w->sha256, now->images[i].sha256);
        else continue;
        say(out, cap, &n, m);
    }
    for (int i = 0; i < was->n_images; i++)
        if (!find_image(now, was->images[i].name)) {
            snprintf(m, sizeof m, "image %s is no longer used", was->images[i].name);
            say(out, cap, &n, m);
        }
    if (!n) say(out, cap, &n, "the order in which the conditions name their images changed");
    return n;
}
