/* SPDX-License-Identifier: MIT
 *
 * Broken plugin (case c): an ordinary shared library that exports a function
 * but no domel entry symbol at all, e.g. a stray .so in a plugin folder.
 */
#if defined(_WIN32)
#define NOT_A_PLUGIN_EXPORT __declspec(dllexport)
#else
#define NOT_A_PLUGIN_EXPORT __attribute__((visibility("default")))
#endif

NOT_A_PLUGIN_EXPORT int not_a_plugin_answer(void) { return 42; }
