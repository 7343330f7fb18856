/* SPDX-License-Identifier: MIT
 *
 * A valid plugin written in plain C (no C++ layer) whose twisting kernel
 * always fails with DOMEL_ERR_RUNTIME and a message. It loads and creates
 * fine; the test proves the host turns the failure into a PluginError that
 * carries the plugin's message instead of crashing (case l). Its contact
 * table has the ABI 2.0 size, to show how the host reads an older table.
 */
#include <domel/sdk/abi.h>

#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>

typedef struct failing_state {
  int calls;
} failing_state;

static domel_status failing_create(const char* params_json, const domel_host_v2* host, void** out_instance,
                                   char* err, size_t err_capacity) {
  failing_state* s;
  (void)params_json;
  (void)host;
  s = (failing_state*)calloc(1, sizeof *s);
  if (s == NULL) {
    snprintf(err, err_capacity, "abi_failing_twisting: out of memory");
    return DOMEL_ERR_PARAMETER;
  }
  *out_instance = s;
  return DOMEL_OK;
}

static void failing_destroy(void* instance) { free(instance); }

static domel_status failing_contact(void* instance, domel_contact_batch_v2* batch, char* err,
                                    size_t err_capacity) {
  failing_state* s = (failing_state*)instance;
  s->calls += 1;
  snprintf(err, err_capacity, "abi_failing_twisting: deliberate failure on a batch of %u contacts",
           (unsigned)batch->n);
  return DOMEL_ERR_RUNTIME;
}

/* The table as an ABI 2.0 plugin has it: it ends after `contact` (no
 * `flags`), so the host zero-fills the rest and hands this stage the masses. */
static const domel_contact_family_v2 kFamily = {
    (uint32_t)(offsetof(domel_contact_family_v2, contact) + sizeof(domel_contact_fn)), 0u, failing_contact};
static const domel_model_v2 kModel = {
    sizeof(domel_model_v2), DOMEL_KIND_TWISTING, "abi_failing_twisting", "1.0.0",
    "ABI test model: its kernel always fails", "{\"type\": \"object\"}",
    failing_create, failing_destroy, &kFamily};
static const domel_model_v2* const kModels[] = {&kModel};
static const domel_library_v2 kLibrary = {
    sizeof(domel_library_v2), DOMEL_ABI_MAJOR, DOMEL_ABI_MINOR, "abi_failing", "1.0.0", 1u, kModels};

DOMEL_EXPORT const domel_library_v2* domel_plugin_entry_v2(void) { return &kLibrary; }
