/* Loader for test-only instrument emulators (see transport_emu.h). The module stays loaded for
 * the life of the process: its code may still be on the stack of an atexit handler (ASan). */
#include "devices/transport_emu.h"

#include <dlfcn.h>
#include <stdlib.h>

csf_status csf_transport_emu_open(const char *device, const char *options, csf_emu_device **out,
                                  csf_error *err)
{
    *out = NULL;
    const char *path = getenv(CSF_EMU_ENV);
    if (!path || !*path)
        return csf_error_set(err, CSF_E_INVALID_ARG, "%s:emulator is for csfcal's own tests: set %s to the "
                             "emulator module (tests/emu) to use it", device, CSF_EMU_ENV);
    void *mod = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!mod) {
        const char *why = dlerror();
        return csf_error_set(err, CSF_E_NOT_FOUND, "%s: cannot load the emulator module %s: %s", device, path,
                             why ? why : "unknown error");
    }
    csf_emu_open_fn open_fn;
    *(void **)&open_fn = dlsym(mod, CSF_EMU_OPEN_SYMBOL);
    if (!open_fn)
        return csf_error_set(err, CSF_E_NOT_FOUND, "%s: %s has no %s: not a csfcal emulator module", device, path,
                             CSF_EMU_OPEN_SYMBOL);
    return open_fn(device, options ? options : "", out, err);
}
