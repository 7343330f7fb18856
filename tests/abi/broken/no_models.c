/* SPDX-License-Identifier: MIT
 *
 * Broken plugin (case f): a well-formed library descriptor with
 * model_count == 0 — a library that registers nothing.
 */
#include <domel/sdk/abi.h>

static const domel_library_v2 kLibrary = {
    sizeof(domel_library_v2), DOMEL_ABI_MAJOR, DOMEL_ABI_MINOR, "no_models", "1.0.0", 0u, NULL};

DOMEL_EXPORT const domel_library_v2* domel_plugin_entry_v2(void) { return &kLibrary; }
