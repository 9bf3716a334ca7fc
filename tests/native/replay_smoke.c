/* A replay through the C ABI alone, for platforms where the CLI and the GoogleTest suites do not
 * build (the Windows DLL under wine): loads a bundle, builds the avatar of a `softdeca replay`
 * output folder (avatar/neutral.obj and avatar/blendshapes/<name>.obj), plays the take's frames
 * through SoftDECA and compares them with that replay's softdeca.pc2 (written on Linux).
 * Usage: replay_smoke BUNDLE REPLAY_DIR TAKE.sdrec FIRST_FRAME FRAMES TOLERANCE_M */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "softdeca/softdeca.h"

static int fail(const char* what) {
  fprintf(stderr, "replay_smoke: %s: %s\n", what, softdeca_last_error());
  return 1;
}

/* Vertices ("v x y z") and triangles ("f a b c", fanned) of an OBJ; returns 0 on failure. */
static int read_obj(const char* path, float** v, uint32_t* nv, int32_t** t, uint32_t* nt) {
  FILE* f = fopen(path, "r");
  char line[512];
  uint32_t cv = 0, ct = 0;
  if (!f) return 0;
  *v = NULL;
  *nv = 0;
  if (t) {
    *t = NULL;
    *nt = 0;
  }
  while (fgets(line, sizeof line, f)) {
    if (line[0] == 'v' && line[1] == ' ') {
      if (*nv == cv) *v = (float*)realloc(*v, sizeof(float) * 3 * (cv = cv ? 2 * cv : 4096));
      if (sscanf(line + 2, "%f %f %f", &(*v)[3 * *nv], &(*v)[3 * *nv + 1], &(*v)[3 * *nv + 2]) != 3) break;
      ++*nv;
    } else if (t && line[0] == 'f' && line[1] == ' ') {
      int32_t c[16];
      int n = 0;
      char* p = line + 2;
      while (n < 16) {
        char* end;
        long i = strtol(p, &end, 10);
        if (end == p) break;
        c[n++] = (int32_t)i - 1;
        p = end;
        while (*p && *p != ' ' && *p != '\t') ++p;
      }
      for (int k = 1; k + 1 < n; ++k) {
        if (*nt == ct) *t = (int32_t*)realloc(*t, sizeof(int32_t) * 3 * (ct = ct ? 2 * ct : 4096));
        (*t)[3 * *nt] = c[0];
        (*t)[3 * *nt + 1] = c[k];
        (*t)[3 * *nt + 2] = c[k + 1];
        ++*nt;
      }
    }
  }
  fclose(f);
  return *nv > 0;
}

int main(int argc, char** argv) {
  if (argc != 7) {
    fprintf(stderr, "usage: replay_smoke BUNDLE REPLAY_DIR TAKE.sdrec FIRST_FRAME FRAMES TOLERANCE_M\n");
    return 2;
  }
  const uint32_t first = (uint32_t)atoi(argv[4]), frames = (uint32_t)atoi(argv[5]);
  const double tolerance = atof(argv[6]);
  char path[4096];
  if (softdeca_abi_version() != SOFTDECA_ABI_VERSION) return fail("ABI version");

  softdeca_model* model = NULL;
  softdeca_model_options options = {sizeof options, 1};
  if (softdeca_model_load(argv[1], &options, &model) != SOFTDECA_OK) return fail("loading the bundle");
  softdeca_model_info info;
  info.struct_size = sizeof info;
  if (softdeca_model_get_info(model, &info) != SOFTDECA_OK) return fail("model info");

  float* neutral;
  int32_t* triangles;
  uint32_t nv, nt;
  snprintf(path, sizeof path, "%s/avatar/neutral.obj", argv[2]);
  if (!read_obj(path, &neutral, &nv, &triangles, &nt) || nv != info.head_vertex_count) {
    fprintf(stderr, "replay_smoke: %s: not the bundle's %u-vertex template\n", path, info.head_vertex_count);
    return 1;
  }
  float* deltas = (float*)calloc((size_t)52 * nv * 3, sizeof(float));
  for (uint32_t s = 0; s < 52; ++s) {
    float* shape;
    uint32_t ns;
    snprintf(path, sizeof path, "%s/avatar/blendshapes/%s.obj", argv[2], softdeca_blendshape_name(s));
    if (!read_obj(path, &shape, &ns, NULL, NULL)) continue;
    for (uint32_t i = 0; i < 3 * nv && ns == nv; ++i) deltas[(size_t)s * nv * 3 + i] = shape[i] - neutral[i];
    free(shape);
  }
  softdeca_avatar_desc desc;
  memset(&desc, 0, sizeof desc);
  desc.struct_size = sizeof desc;
  desc.neutral = neutral;
  desc.vertex_count = nv;
  desc.triangles = triangles;
  desc.triangle_count = nt;
  desc.blendshapes = deltas;
  desc.blendshape_count = 52;
  desc.threads = 1;
  softdeca_avatar* avatar = NULL;
  if (softdeca_avatar_create(model, &desc, &avatar) != SOFTDECA_OK) return fail("creating the avatar");
  softdeca_model_destroy(model); /* the avatar keeps what it needs */
  if (softdeca_avatar_prepare(avatar) != SOFTDECA_OK) return fail("prepare");

  snprintf(path, sizeof path, "%s/softdeca.pc2", argv[2]);
  FILE* pc2 = fopen(path, "rb");
  int32_t header[8];
  if (!pc2 || fread(header, 4, 8, pc2) != 8 || header[4] != (int32_t)nv) {
    fprintf(stderr, "replay_smoke: %s: not a point cache of %u points\n", path, nv);
    return 1;
  }
  softdeca_player* player = NULL;
  if (softdeca_player_open(argv[3], &player) != SOFTDECA_OK) return fail("opening the take");
  softdeca_recording_info rec;
  rec.struct_size = sizeof rec;
  if (softdeca_player_info(player, &rec) != SOFTDECA_OK) return fail("take info");

  float* out = (float*)malloc(sizeof(float) * 3 * nv);
  float* want = (float*)malloc(sizeof(float) * 3 * nv);
  softdeca_output output = {sizeof output, out, nv, NULL, 0};
  softdeca_frame frame;
  frame.struct_size = sizeof frame;
  uint32_t usable = 0, done = 0;
  double worst = 0;
  for (uint32_t i = 0; i < rec.frame_count && done < frames; ++i) {
    if (softdeca_player_frame(player, i, &frame) != SOFTDECA_OK) return fail("take frame");
    if (frame.tracking == SOFTDECA_TRACKING_LOST || usable++ < first) continue;
    for (int s = 0; s < 52; ++s) frame.weights[s] = frame.weights[s] < 0 ? 0 : frame.weights[s] > 1 ? 1 : frame.weights[s];
    if (softdeca_avatar_evaluate_weights(avatar, frame.weights, 52, &output) != SOFTDECA_OK) return fail("frame");
    if (fread(want, sizeof(float), 3 * (size_t)nv, pc2) != 3 * (size_t)nv) {
      fprintf(stderr, "replay_smoke: the point cache ends before frame %u\n", done);
      return 1;
    }
    for (uint32_t k = 0; k < 3 * nv; ++k) worst = fmax(worst, fabs((double)out[k] - want[k]));
    ++done;
  }
  softdeca_player_destroy(player);
  softdeca_avatar_destroy(avatar);
  fclose(pc2);
  printf("replay_smoke: softdeca %s, %u SoftDECA frames of %u vertices, largest difference from the reference %.3g m "
         "(tolerance %.3g m)\n",
         softdeca_version(), done, nv, worst, tolerance);
  return done == frames && worst <= tolerance ? 0 : 1;
}
