/* SPDX-License-Identifier: MIT
 *
 * Broken plugin (case h): a rolling model whose params_schema_json is not
 * JSON at all (unterminated object, bare word). The loader parses every
 * schema at load time and must refuse the library then, not at first use.
 */
#include "stub_callbacks.h"

static const domel_model_v2 kModel = {
    sizeof(domel_model_v2), DOMEL_KIND_ROLLING, "bad_schema_rolling", "1.0.0", "schema is not JSON",
    "{\"type\": object", stub_create, stub_destroy, &stub_contact_family};
static const domel_model_v2* const kModels[] = {&kModel};
static const domel_library_v2 kLibrary = {
    sizeof(domel_library_v2), DOMEL_ABI_MAJOR, DOMEL_ABI_MINOR, "bad_schema", "1.0.0", 1u, kModels};

DOMEL_EXPORT const domel_library_v2* domel_plugin_entry_v2(void) { return &kLibrary; }
