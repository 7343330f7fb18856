/* SPDX-License-Identifier: MIT
 *
 * Shared by the hand-written C plugins of the ABI refusal tests: do-nothing
 * callbacks (create, destroy, contact, and a contact family table holding
 * the contact one) so each broken library only spells out
 * the one thing that is wrong with it. Plain C against abi.h, no C++ layer:
 * it also shows the ABI is usable from C. Everything here is static, so no
 * symbol beyond a library's own entry point is exported.
 */
#ifndef DOMEL_ABI_TEST_STUB_CALLBACKS_H
#define DOMEL_ABI_TEST_STUB_CALLBACKS_H

#include <domel/sdk/abi.h>

static int stub_instance_storage;

static domel_status stub_create(const char* params_json, const domel_host_v2* host, void** out_instance,
                                char* err, size_t err_capacity) {
  (void)params_json;
  (void)host;
  (void)err;
  (void)err_capacity;
  *out_instance = &stub_instance_storage;
  return DOMEL_OK;
}

static void stub_destroy(void* instance) { (void)instance; }

static domel_status stub_contact(void* instance, domel_contact_batch_v2* batch, char* err,
                                 size_t err_capacity) {
  (void)instance;
  (void)batch;
  (void)err;
  (void)err_capacity;
  return DOMEL_OK;
}

/* Only some libraries use the table; unused there, hence the attribute. */
__attribute__((unused)) static const domel_contact_family_v2 stub_contact_family = {
    sizeof(domel_contact_family_v2), 0u, stub_contact};

#define STUB_SCHEMA "{\"type\": \"object\"}"

#endif /* DOMEL_ABI_TEST_STUB_CALLBACKS_H */
