/* Compiles the public header as strict C (and, through abi_header_check.cpp, as C++) and
 * checks the ABI convention its top comment states: struct_size first in every struct passed by
 * pointer, 32-bit booleans and counts, void destroy functions that accept NULL, and the ABI
 * version of the header matching the library's. */
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "softdeca/softdeca.h"

#define SOFTDECA_CAT2(a, b) a##b
#define SOFTDECA_CAT(a, b) SOFTDECA_CAT2(a, b)
/* A compile-time check that works at file scope in C99 and C++. */
#define ABI_CHECK(cond) typedef char SOFTDECA_CAT(abi_check_, __LINE__)[(cond) ? 1 : -1]
#define SIZE_FIRST(T) \
  ABI_CHECK(offsetof(T, struct_size) == 0 && sizeof(((T*)0)->struct_size) == sizeof(uint32_t))

ABI_CHECK(sizeof(softdeca_bool) == 4);
ABI_CHECK(SOFTDECA_ABI_VERSION >= 1);
SIZE_FIRST(softdeca_model_options);
SIZE_FIRST(softdeca_model_info);
SIZE_FIRST(softdeca_avatar_desc);
SIZE_FIRST(softdeca_output);
SIZE_FIRST(softdeca_stats);
SIZE_FIRST(softdeca_avatar_mesh);
SIZE_FIRST(softdeca_fit_options);
SIZE_FIRST(softdeca_parameter_info);
SIZE_FIRST(softdeca_sim_collision_set);
SIZE_FIRST(softdeca_sim_mesh);
SIZE_FIRST(softdeca_sim_settings);
SIZE_FIRST(softdeca_sim_frame);
SIZE_FIRST(softdeca_sim_stats);
SIZE_FIRST(softdeca_frame);
SIZE_FIRST(softdeca_receiver_config);
SIZE_FIRST(softdeca_receiver_stats);
SIZE_FIRST(softdeca_recording_header);
SIZE_FIRST(softdeca_recording_info);
SIZE_FIRST(softdeca_convert_report);

/* Destroy functions: void, one handle argument (a mismatch is a compile error in C++ and a
 * -Werror=incompatible-pointer-types error in C). */
typedef void (*model_destroy_fn)(softdeca_model*);
typedef void (*avatar_destroy_fn)(softdeca_avatar*);
typedef void (*sim_destroy_fn)(softdeca_sim*);
typedef void (*receiver_destroy_fn)(softdeca_receiver*);
typedef void (*recorder_destroy_fn)(softdeca_recorder*);
typedef void (*player_destroy_fn)(softdeca_player*);

/* `--sizes`: sizeof every struct of the ABI, one "name size" line each, for bindings' layout
 * tests (the C# tests compare their structs against these). */
static int print_sizes(void) {
#define PRINT_SIZE(T) printf("%s %u\n", #T, (unsigned)sizeof(T))
  PRINT_SIZE(softdeca_model_options);
  PRINT_SIZE(softdeca_model_info);
  PRINT_SIZE(softdeca_avatar_desc);
  PRINT_SIZE(softdeca_output);
  PRINT_SIZE(softdeca_stats);
  PRINT_SIZE(softdeca_avatar_mesh);
  PRINT_SIZE(softdeca_fit_options);
  PRINT_SIZE(softdeca_parameter_info);
  PRINT_SIZE(softdeca_pose);
  PRINT_SIZE(softdeca_frame);
  PRINT_SIZE(softdeca_receiver_config);
  PRINT_SIZE(softdeca_receiver_stats);
  PRINT_SIZE(softdeca_recording_header);
  PRINT_SIZE(softdeca_recording_info);
  PRINT_SIZE(softdeca_convert_report);
#undef PRINT_SIZE
  return 0;
}

int main(int argc, char** argv) {
  if (argc == 2 && strcmp(argv[1], "--sizes") == 0) return print_sizes();
  model_destroy_fn model_destroy = softdeca_model_destroy;
  avatar_destroy_fn avatar_destroy = softdeca_avatar_destroy;
  sim_destroy_fn sim_destroy = softdeca_sim_destroy;
  receiver_destroy_fn receiver_destroy = softdeca_receiver_destroy;
  recorder_destroy_fn recorder_destroy = softdeca_recorder_destroy;
  player_destroy_fn player_destroy = softdeca_player_destroy;
  model_destroy(NULL);
  avatar_destroy(NULL);
  sim_destroy(NULL);
  receiver_destroy(NULL);
  recorder_destroy(NULL);
  player_destroy(NULL);
  if (softdeca_abi_version() != SOFTDECA_ABI_VERSION) {
    fprintf(stderr, "library ABI version %u, header %u\n", (unsigned)softdeca_abi_version(),
            (unsigned)SOFTDECA_ABI_VERSION);
    return 1;
  }
  {
    /* The struct rule: a struct_size below the library's is refused with a message. */
    softdeca_receiver_config config;
    config.struct_size = 4;
    if (softdeca_receiver_config_init(&config) != SOFTDECA_ERROR_INVALID_ARGUMENT) return 1;
    if (softdeca_last_error()[0] == '\0') return 1;
    config.struct_size = (uint32_t)sizeof config;
    if (softdeca_receiver_config_init(&config) != SOFTDECA_OK) return 1;
  }
  printf("softdeca.h compiles and holds its ABI convention (ABI version %u)\n", (unsigned)SOFTDECA_ABI_VERSION);
  return 0;
}
