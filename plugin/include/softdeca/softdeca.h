/*
 * SoftDECA native library: the public C ABI.
 *
 * This header is the way into the library for every host: Unity (P/Invoke), Python (ctypes)
 * and the command line (docs/ARCHITECTURE.md, "Ways into the native library").
 * Kept whole: every binding and the mirror tests read the whole C ABI from this one file.
 *
 * ABI CONVENTION (holds for every declaration below; a binding can rely on it mechanically):
 *   1. Versions. SOFTDECA_ABI_VERSION is the version of this convention and of every signature
 *      and struct layout below; softdeca_abi_version() returns the loaded library's. A binding
 *      compares the two at load and refuses a mismatch. It changes with any incompatible edit.
 *   2. Structs passed by pointer start with `uint32_t struct_size`, which the caller sets to
 *      sizeof(the struct) (output structs too, and *_init functions expect it set). The library
 *      rejects a smaller struct_size with SOFTDECA_ERROR_INVALID_ARGUMENT and a message naming
 *      the struct and both sizes; it reads and writes only the fields it knows, so fields are
 *      only ever appended. Structs are plain data: fixed-width integers, float, double,
 *      pointers, fixed arrays; no bool, no bit fields, no size_t, no enum-typed fields (enums
 *      travel as int32_t).
 *   3. Every function returns a softdeca_status, except: the *_destroy functions, which return
 *      void and accept NULL (a no-op); and the static queries softdeca_abi_version,
 *      softdeca_version, softdeca_last_error, softdeca_status_name and softdeca_blendshape_get_name.
 *      On failure the reason is available from softdeca_last_error() on the same thread, and
 *      output buffers are left untouched.
 *   4. Booleans are softdeca_bool (int32_t): 0 is false, 1 is true; inputs take any non-zero
 *      value as true.
 *   5. Counts, capacities, sizes in bytes and element indices are uint32_t. Arrays of indices
 *      into meshes (triangles, tetrahedra, vertex lists, landmark profiles) are int32_t.
 *      Only running totals in *_stats structs (frames, datagrams, bytes) are uint64_t.
 *   6. Parameters: every parameter list has a count, a softdeca_parameter_info by index and a
 *      lookup by name (softdeca_sim_find_parameter for the simulator's, softdeca_model_find_parameter
 *      for a bundle's). Every function that reads or writes a parameter takes its uint32_t
 *      index, so any parameter is addressable by index directly and by name through the lookup.
 *      Scalar parameter values are double; per-element maps are float arrays. A parameter's
 *      description has the same field names in every language: name, unit, domain,
 *      description, default_value, minimum, maximum, log_scale (C#: the same words in
 *      PascalCase); never min/max (macros of <windows.h>) nor lo/hi.
 *   7. Every array argument comes with its element count; null pointers, wrong sizes and
 *      non-finite values are rejected with a status, never with a crash or an exception.
 *   8. No callbacks into the caller; strings are NUL-terminated UTF-8, owned by the library when
 *      returned (their lifetime is stated) and copied when passed in.
 *   9. Names. A function is softdeca_<noun>_<verb>[_<what>]: the noun is the handle it acts on
 *      (model, avatar, avatar_fit, sim, player, receiver, recorder) or the list it reads
 *      (blendshape), written once and first. A handle is made by _create (from values) or _load
 *      (from a file or bytes: a bundle, a saved fit, a recording; _load_memory for bytes) and
 *      released by _destroy. Reading is _get_<what> (_get_<what>_count for a count), changing
 *      is _set_<what>, finding an index by name is _find_<what>; every other verb says what
 *      the call does (evaluate, prepare, calibrate, reset, save, seek, advance, write, start,
 *      stop, request, solve, step). A struct's defaults come from <struct>_init. Calls on no
 *      handle start with their verb (softdeca_convert_..., softdeca_export_...,
 *      softdeca_embed_points, softdeca_compute_tet_volumes), and four library-wide queries keep
 *      the C idiom: softdeca_abi_version, softdeca_version, softdeca_last_error and
 *      softdeca_status_name. tests/python/test_abi_names.py holds every declaration to this.
 *  10. Library defaults. Where the library chooses a setting's value itself (softdeca_precision),
 *      the enum's zero means that choice (SOFTDECA_PRECISION_DEFAULT = 0), so a zero-initialised
 *      struct gets the library's defaults. A binding passes the zero on and never restates
 *      which value it stands for: the choice is the library's, and may differ per model.
 *
 * Units are metres; the frame is right-handed, +Y up, +Z out of the face (ARKit's face-anchor
 * frame). Arrays of 3D points are packed xyz floats. The library keeps no global mutable state
 * (the last-error text is thread-local).
 */
#ifndef SOFTDECA_SOFTDECA_H
#define SOFTDECA_SOFTDECA_H

#include <stddef.h>
#include <stdint.h>

#if defined(_WIN32)
#  if defined(SOFTDECA_BUILDING)
#    define SOFTDECA_API __declspec(dllexport)
#  else
#    define SOFTDECA_API __declspec(dllimport)
#  endif
#else
#  define SOFTDECA_API __attribute__((visibility("default")))
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ---- Status and errors ---------------------------------------------------------------- */

typedef enum softdeca_status {
  SOFTDECA_OK = 0,
  SOFTDECA_ERROR_INVALID_ARGUMENT = 1, /* null pointer, wrong size, out-of-range value   */
  SOFTDECA_ERROR_NON_FINITE = 2,       /* NaN or infinity in an input array              */
  SOFTDECA_ERROR_BUFFER_TOO_SMALL = 3, /* an output buffer is shorter than required      */
  SOFTDECA_ERROR_IO = 4,               /* a file could not be read or written            */
  SOFTDECA_ERROR_FORMAT = 5,           /* malformed or incompatible data                 */
  SOFTDECA_ERROR_INTERNAL = 6,         /* unexpected failure inside the library          */
  SOFTDECA_ERROR_BUSY = 7,             /* the handle is in use by another thread         */
  SOFTDECA_ERROR_NOT_READY = 8         /* a required earlier step has not run (prepare)  */
} softdeca_status;

/* The version of the ABI convention and signatures in this header; see softdeca_abi_version. */
#define SOFTDECA_ABI_VERSION 5u

/* softdeca_bool: 0 false, 1 true (inputs: non-zero is true). */
typedef int32_t softdeca_bool;
#define SOFTDECA_FALSE 0
#define SOFTDECA_TRUE 1

/* SOFTDECA_ABI_VERSION of the library as built: a binding checks it at load. */
SOFTDECA_API uint32_t softdeca_abi_version(void);

/* Library version as "MAJOR.MINOR.PATCH". The pointer is static and never freed. */
SOFTDECA_API const char* softdeca_version(void);

/* Text describing the last failure of a softdeca_* call on the calling thread ("" if none).
 * Valid until the next softdeca_* call on this thread. */
SOFTDECA_API const char* softdeca_last_error(void);

/* Human-readable name of a status code (static string). */
SOFTDECA_API const char* softdeca_status_name(softdeca_status status);

/* ==== Runtime: SoftDECA and SparseSoftDECA per frame ===================================
 * A model bundle (docs/bundle.md) is loaded once into a softdeca_model; each head is a
 * softdeca_avatar made from a model and the host's own mesh. Per avatar:
 *   create -> set parameters (optional) -> prepare -> evaluate every frame.
 * prepare computes the hyper-tensors L(p, h), the dynamics coefficients and (first time) the
 * deformation-transfer factorisation; with a bundle's rest physics (format version 4) and
 * parameters away from their defaults it also simulates the avatar's head at rest (about a
 * second; docs/runtime.md "Physics at prepare"). It may run on a worker thread while frames keep
 * using the previous preparation: a frame uses exactly one preparation (never a mix), and picks
 * up a new one at its start once prepare has returned.
 *
 * Threads: a model may be used from any number of threads. An avatar's evaluate_* and
 * calibrate calls must come from one thread at a time (a concurrent call fails with
 * SOFTDECA_ERROR_BUSY instead of racing); prepare, the parameter and identity setters,
 * set/reset dynamics and get_stats may be called from any thread, also during a frame. Different
 * avatars are independent and run in parallel. Destroy a handle only when no call on it runs.
 * A model may be destroyed before its avatars: they keep what they need.
 *
 * Arrays of points are xyz floats in metres in the face-anchor frame; counts are in elements
 * (vertices, triangles, weights) unless stated. Vertex order is the template's (the bundle's
 * head_vertex_count vertices; the first skin_vertex_count are the skin surface S).
 * On failure, output buffers are left untouched: the last good output stays valid. */

typedef struct softdeca_model softdeca_model;
typedef struct softdeca_avatar softdeca_avatar;

/* The newest bundle format version this library reads (manifest "format_version"); it reads
 * every version from 1 up to it. Version 2 adds SoftDECA's optional vertex stage, version 3
 * its optional residual stage, version 4 the optional physics at prepare (rest_physics),
 * version 5 the optional template head for fitting users' avatars (template_head), version 6
 * SoftDECA's optional rest gate (rest_gate), version 7 SoftDECA trained on the rest physics
 * (rest_changes). */
#define SOFTDECA_BUNDLE_FORMAT_VERSION 7

typedef struct softdeca_model_options {
  uint32_t struct_size;            /* sizeof(softdeca_model_options) */
  uint32_t prepare_threads; /* ONNX Runtime threads for the per-avatar networks; 0: 1 */
  uint32_t memory_budget_mib; /* most a bundle's networks may ask for, in MiB, checked before
                               * loading them (docs/security.md); 0: 2048 */
} softdeca_model_options;

/* Loads a bundle from a folder or from a .tar of its files. `options` may be NULL.
 * SOFTDECA_ERROR_IO: unreadable path; SOFTDECA_ERROR_FORMAT: wrong format or version, sizes that
 * disagree, damaged ONNX files (the message names the file and the problem). */
SOFTDECA_API softdeca_status softdeca_model_load(const char* path, const softdeca_model_options* options,
                                                 softdeca_model** out_model);

/* The same from memory: an uncompressed tar (ustar) of the bundle's files, e.g. a Unity
 * TextAsset's bytes. The bytes are copied; the caller may free them on return. */
SOFTDECA_API softdeca_status softdeca_model_load_memory(const void* data, uint32_t byte_count,
                                                        const softdeca_model_options* options,
                                                        softdeca_model** out_model);

/* Releases the caller's reference. NULL is a no-op. */
SOFTDECA_API void softdeca_model_destroy(softdeca_model* model);

typedef struct softdeca_model_info {
  uint32_t struct_size; /* sizeof(softdeca_model_info) */
  uint32_t format_version;
  uint32_t head_vertex_count;   /* vertices of the whole head (template topology)  */
  uint32_t skin_vertex_count;   /* the first skin_vertex_count of them are S       */
  uint32_t skin_triangle_count; /* triangles of S (the bundle's triangulation)     */
  uint32_t latent_size;
  uint32_t identity_size;
  uint32_t blendshape_count;   /* 52, canonical ARKit order                       */
  uint32_t parameter_count;
  uint32_t landmark_count;     /* landmarks SparseSoftDECA reads                  */
  uint32_t arkit_vertex_count; /* vertices of ARKit's face mesh (1220)            */
  softdeca_bool has_softdeca;  /* evaluate_weights/evaluate_surface available      */
  softdeca_bool has_sparse;    /* evaluate_landmarks available                     */
  softdeca_bool untrained;     /* random weights (tests, demos): not a model       */
  float dynamics_frame_rate_hz; /* the frame rate the dynamics were trained at; 0: unknown */
} softdeca_model_info;

SOFTDECA_API softdeca_status softdeca_model_get_info(const softdeca_model* model, softdeca_model_info* out_info);

/* Parameter `index` of the bundle (its manifest's list, which the runtime reads instead of the
 * compiled-in one), in the simulator's softdeca_parameter_info (declared with the physics
 * simulator below; set struct_size). Strings are owned by the model and stay valid while it or
 * an avatar made from it lives. Per-face / per-vertex maps are accepted unless domain is
 * "global". */
struct softdeca_parameter_info;
SOFTDECA_API softdeca_status softdeca_model_get_parameter_info(const softdeca_model* model, uint32_t index,
                                                          struct softdeca_parameter_info* out_info);
/* Index of a parameter by name; SOFTDECA_ERROR_INVALID_ARGUMENT if there is none. */
SOFTDECA_API softdeca_status softdeca_model_find_parameter(const softdeca_model* model, const char* name,
                                                           uint32_t* out_index);
/* The ARKit face-mesh vertex index of every landmark (landmark_count int32), so a host can send
 * just those vertices to evaluate_landmarks. */
SOFTDECA_API softdeca_status softdeca_model_get_landmark_vertices(const softdeca_model* model,
                                                                  int32_t* out_vertices, uint32_t capacity);

/* The bundle's triangulation of the skin S (skin_triangle_count * 3 int32 indices): the face
 * order of per-face parameter maps. */
SOFTDECA_API softdeca_status softdeca_model_get_skin_triangles(const softdeca_model* model, int32_t* out_triangles,
                                                               uint32_t capacity);

/* The landmarks on a mesh in template topology (skin_vertex_count or head_vertex_count
 * vertices): landmark_count points from the bundle's barycentric definition on S. For hosts
 * that drive SparseSoftDECA from their own rig, and to show where the landmarks sit. */
SOFTDECA_API softdeca_status softdeca_model_evaluate_landmarks(const softdeca_model* model, const float* vertices,
                                                               uint32_t vertex_count, float* out_points,
                                                               uint32_t point_capacity);

/* How an avatar stores a model's per-element tables (its hyper-tensor; SoftDECA's vertex and
 * residual stages too). DEFAULT is each model's own, within that model's parity bound
 * (docs/runtime.md): int8 for SoftDECA (on the shipped bundle it adds at most 0.0051 mm to
 * float storage's frames and reads half of half's bytes), half for SparseSoftDECA (int8 would
 * add 0.025 mm, over its 0.02 mm bound). */
typedef enum softdeca_precision {
  SOFTDECA_PRECISION_DEFAULT = 0, /* the model's default, above */
  SOFTDECA_PRECISION_HALF = 1,    /* binary16: half of float */
  SOFTDECA_PRECISION_FLOAT = 2,   /* binary32 */
  SOFTDECA_PRECISION_INT8 = 3     /* int8 with a scale per 8 elements and latent: a quarter of float */
} softdeca_precision;

typedef struct softdeca_avatar_fit softdeca_avatar_fit; /* opaque: a user's own avatar, below */

/* An avatar mesh in its own coordinates (right-handed: a left-handed host mirrors one axis)
 * and its own units. The mesh may be several parts (head, eyes, teeth, body) concatenated.
 * A mesh in the bundle's template topology (the template path) has head_vertex_count vertices,
 * is in metres in the library's frame, and may come without shapes (blendshapes NULL,
 * blendshape_count 0: then only evaluate_surface and evaluate_landmarks run). */
typedef struct softdeca_avatar_mesh {
  uint32_t struct_size;      /* sizeof(softdeca_avatar_mesh) */
  const float* neutral;      /* vertex_count * 3 floats */
  uint32_t vertex_count;     /* 3 .. SOFTDECA_MAX_AVATAR_VERTICES */
  const int32_t* triangles;  /* triangle_count * 3 vertex indices */
  uint32_t triangle_count;
  const float* blendshapes;  /* 52 * vertex_count * 3 floats: the rig's ARKit shapes as deltas in
                                canonical order; a shape the rig lacks is all zeros (found by
                                softdeca_blendshape_find_index from the rig's own names) */
  uint32_t blendshape_count; /* 52 (0 with blendshapes NULL: the template path only) */
  const float* landmarks;    /* NULL, or landmark_count * 3 floats: the bundle's landmarks on the
                                avatar's neutral, in the bundle's order (optional guides; needed
                                only for a rig without ARKit shapes) */
  uint32_t landmark_count;   /* 0 or the bundle's landmark_count (for the fit; an avatar ignores
                                them) */
} softdeca_avatar_mesh;

#define SOFTDECA_MAX_AVATAR_VERTICES 4000000u

/* One avatar, whichever mesh the user has: a mesh in the template's topology with no fit (the
 * template path), or any mesh with the fit made for it (softdeca_avatar_fit_create or _load;
 * checked by a hash of the mesh's neutral and triangles: a changed mesh is refused with
 * SOFTDECA_ERROR_FORMAT). Every softdeca_avatar_* call then works in the mesh's own vertices
 * (outputs hold vertex_count vertices; parameter maps are given per mesh triangle or vertex),
 * except evaluate_surface, which takes a surface in the template's topology (no fit). */
typedef struct softdeca_avatar_desc {
  uint32_t struct_size;               /* sizeof(softdeca_avatar_desc) */
  const softdeca_avatar_mesh* mesh;   /* the avatar's mesh (its arrays are copied) */
  const softdeca_avatar_fit* fit;     /* NULL: mesh is in the template's topology; else mesh's fit */
  uint32_t threads;                   /* threads per frame: 0 or 1 the caller only; 2 or more: the
                                         caller plus helper threads owned by the avatar (max 8) */
  int32_t precision;                  /* softdeca_precision of SoftDECA's tables (per-face
                                         hyper-tensor, vertex and residual stages) */
  int32_t sparse_precision;           /* softdeca_precision of SparseSoftDECA's hyper-tensor */
} softdeca_avatar_desc;

/* Checks the mesh (sizes, finite values, indices, no degenerate skin triangle) and runs the
 * bundle's identity encoder on the neutral skin (softdeca_avatar_get_identity). */
SOFTDECA_API softdeca_status softdeca_avatar_create(const softdeca_model* model, const softdeca_avatar_desc* desc,
                                                    softdeca_avatar** out_avatar);
/* NULL is a no-op. */
SOFTDECA_API void softdeca_avatar_destroy(softdeca_avatar* avatar);

/* Material parameters (see softdeca_model_get_parameter_info), effective at the next prepare.
 * A global value replaces any map. Maps give one value per skin triangle (skin_triangle_count,
 * in the bundle's triangulation) or per skin vertex (skin_vertex_count); the other element
 * kind is derived (face -> vertex: area-weighted mean of the incident faces; vertex -> face:
 * mean of the corners). Values outside [min, max] are rejected. */
SOFTDECA_API softdeca_status softdeca_avatar_set_parameter(softdeca_avatar* avatar, uint32_t index, double value);
SOFTDECA_API softdeca_status softdeca_avatar_set_parameter_faces(softdeca_avatar* avatar, uint32_t index,
                                                                 const float* values, uint32_t face_count);
SOFTDECA_API softdeca_status softdeca_avatar_set_parameter_vertices(softdeca_avatar* avatar, uint32_t index,
                                                                    const float* values, uint32_t vertex_count);
SOFTDECA_API softdeca_status softdeca_avatar_reset_parameters(softdeca_avatar* avatar);
/* The global value (a map's parameters report their last global value) and whether a map is set;
 * either output may be NULL. */
SOFTDECA_API softdeca_status softdeca_avatar_get_parameter(const softdeca_avatar* avatar, uint32_t index,
                                                           double* out_value, softdeca_bool* out_localised);

/* The identity code h (identity_size floats): from the encoder, or as set; set takes effect at
 * the next prepare. */
SOFTDECA_API softdeca_status softdeca_avatar_get_identity(const softdeca_avatar* avatar, float* out_identity,
                                                          uint32_t capacity);
SOFTDECA_API softdeca_status softdeca_avatar_set_identity(softdeca_avatar* avatar, const float* identity,
                                                          uint32_t count);

/* Builds a new preparation from the current parameters and identity and publishes it (with the
 * bundle's rest physics, a static solve of the avatar's head at rest when a parameter is away
 * from its default: run it off the frame thread). */
SOFTDECA_API softdeca_status softdeca_avatar_prepare(softdeca_avatar* avatar);

/* Where a frame's result goes: vertices of the whole head, and optionally unit normals. */
typedef struct softdeca_output {
  uint32_t struct_size;          /* sizeof(softdeca_output) */
  float* vertices;        /* vertex_capacity * 3 floats */
  uint32_t vertex_capacity; /* at least head_vertex_count */
  float* normals;         /* NULL, or normal_capacity * 3 floats */
  uint32_t normal_capacity;
} softdeca_output;

/* SoftDECA from 52 weights in [0, 1] (canonical ARKit order): the avatar's blendshapes give
 * S_t, the model corrects the skin; non-skin vertices (teeth, eyes, ...) follow the blendshapes.
 * Needs blendshapes at creation and a preparation (SOFTDECA_ERROR_NOT_READY). */
SOFTDECA_API softdeca_status softdeca_avatar_evaluate_weights(softdeca_avatar* avatar, const float* weights,
                                                              uint32_t weight_count, const softdeca_output* output);

/* SoftDECA frames of several avatars in one call: as softdeca_avatar_evaluate_weights on each
 * in turn, except that the per-frame networks run once for all avatars of one model (and the
 * residual stage's once for those set to the same parameters), so their weights are read once a
 * call instead of once an avatar; each avatar's frame equals its own call's. Crowds and
 * collaborations driving several faces of one bundle gain the most.
 * avatars: avatar_count handles (1 to 4096); weights: avatar_count x weight_count floats, avatar
 * i's at weights + i * weight_count (weight_count is 52); outputs: avatar_count outputs;
 * statuses: avatar_count statuses, each avatar's as its own call would return it (its message,
 * the first failing avatar's, from softdeca_last_error). Returns SOFTDECA_OK once every avatar
 * was evaluated, whatever each frame's status; a failure of the call itself (null arrays, a
 * count out of range, a frame network that fails to run) evaluates none and leaves every output
 * untouched. Unlike a single frame, the call allocates its working arrays. */
SOFTDECA_API softdeca_status softdeca_avatar_evaluate_weights_batch(softdeca_avatar* const* avatars, uint32_t avatar_count,
                                                                    const float* weights, uint32_t weight_count,
                                                                    const softdeca_output* outputs, int32_t* statuses);

/* SoftDECA on a caller-blended S_t: `surface` holds the skin (skin_vertex_count) or the whole
 * head (head_vertex_count); `weights` still drive f_w. Non-skin vertices come from a whole-head
 * surface, else they follow the skin rigidly (cranium fixed, jaw with the jaw anchors). */
SOFTDECA_API softdeca_status softdeca_avatar_evaluate_surface(softdeca_avatar* avatar, const float* weights,
                                                              uint32_t weight_count, const float* surface,
                                                              uint32_t vertex_count, const softdeca_output* output);

/* Landmark calibration: the user's neutral face, as the landmark_count landmarks or the whole
 * ARKit face mesh (arkit_vertex_count vertices). Later frames are retargeted: offsets from this
 * neutral, mapped by the similarity between the user's and the avatar's neutral landmarks.
 * Without calibration, evaluate_landmarks takes its points as the avatar's own landmarks. */
SOFTDECA_API softdeca_status softdeca_avatar_calibrate_landmarks(softdeca_avatar* avatar, const float* points,
                                                                 uint32_t point_count);

/* SparseSoftDECA from tracked landmarks (landmark_count points, or the arkit_vertex_count
 * vertices of ARKit's face mesh); non-skin vertices follow the skin rigidly. */
SOFTDECA_API softdeca_status softdeca_avatar_evaluate_landmarks(softdeca_avatar* avatar, const float* points,
                                                                uint32_t point_count, const softdeca_output* output);

/* Plain linear blendshapes and normals (the baseline, and a fallback); needs no preparation. */
SOFTDECA_API softdeca_status softdeca_avatar_evaluate_linear(softdeca_avatar* avatar, const float* weights,
                                                             uint32_t weight_count, const softdeca_output* output);

/* Second-order dynamics on (true) or off (false, the default); reset forgets the past frames (the next
 * frame starts at rest). Changing model between frames also starts at rest. */
SOFTDECA_API softdeca_status softdeca_avatar_set_dynamics(softdeca_avatar* avatar, softdeca_bool enabled);
SOFTDECA_API softdeca_status softdeca_avatar_reset_dynamics(softdeca_avatar* avatar);

typedef struct softdeca_stats {
  uint32_t struct_size;              /* sizeof(softdeca_stats) */
  uint32_t threads;           /* threads a frame uses */
  uint64_t frames;            /* successful evaluations */
  uint64_t preparations;      /* completed prepares */
  uint64_t generation;        /* the preparation the last frame used */
  double frame_ms;            /* the last frame, whole call */
  double encoder_ms;          /* f_w or f_l (ONNX Runtime) */
  double blend_ms;            /* linear blendshapes (or copying the caller's surface) */
  double hyper_ms;            /* z . L: deformation gradients and right-hand sides, or offsets */
  double solve_ms;            /* deformation-transfer solve */
  double dynamics_ms;         /* dynamics and output checks */
  double output_ms;           /* writing the head, non-skin vertices */
  double normals_ms;
  double prepare_ms;          /* the last prepare, whole call */
  double prepare_networks_ms; /* its networks (f_ph, f_ph_v, f_dyn) */
  double factorisation_ms;    /* deformation-transfer assembly and factorisation */
  uint64_t memory_bytes;      /* memory the avatar holds (preparation, factor, buffers) */
  double prepare_physics_ms;  /* its physics at rest (bundles with rest physics; 0 at the defaults) */
  uint32_t physics_iterations; /* solver iterations of that solve (0: none ran) */
  uint32_t reserved;
  uint64_t frame_bytes;       /* the least bytes the last frame read and wrote in memory: the
                                 tables its stages read at their stored size (blendshape deltas
                                 of the moved shapes, hyper-tensors, correction bases, the DT
                                 factor, the per-frame networks' weights, normals topology), its
                                 input vertices and its output, each once (docs/runtime.md) */
} softdeca_stats;

SOFTDECA_API softdeca_status softdeca_avatar_get_stats(const softdeca_avatar* avatar, softdeca_stats* out_stats);

/* ---- A user's own avatar: fitting and the fitted avatar -------------------------------
 * Any ARKit-rigged mesh (any topology, a head or a whole body, any unit and axis convention)
 * is fitted once to the bundle's template: the face, its axes and unit are read off its own
 * ARKit shapes, the template's skin is registered to the face, and every avatar vertex that
 * follows the face is embedded on the registered template. A fitted avatar then runs
 * SoftDECA and SparseSoftDECA on the registered template and returns the avatar's own
 * vertices: its own linear blend plus the physics' correction carried through the embedding
 * (docs/avatars.md). Vertices away from the face move exactly as the avatar's rig moves them.
 * Needs a bundle with the template head (format version 5). The avatar is made by
 * softdeca_avatar_create with the fit in its softdeca_avatar_desc. */

typedef struct softdeca_fit_options {
  uint32_t struct_size;     /* sizeof(softdeca_fit_options) */
  double metres_per_unit;   /* 0: read off the shapes (snapped to mm, cm, inch, dm, m); else
                               1e-6 (a micrometre) to 1000 */
  uint32_t iterations;      /* registration iterations; 0: the default */
  uint32_t reserved;
} softdeca_fit_options;

/* Fills *options with the defaults (struct_size must be set). */
SOFTDECA_API softdeca_status softdeca_fit_options_init(softdeca_fit_options* options);

/* Fits an avatar to the model's template (seconds for a 20k-vertex body). Errors name the
 * problem: no ARKit shape moves a vertex, no face found, NaN vertices, degenerate triangles,
 * shapes of the wrong size. options may be NULL (the defaults). A fit that fails the quality
 * bounds is still made, for the host to inspect: its report's "quality" says so and why. */
SOFTDECA_API softdeca_status softdeca_avatar_fit_create(const softdeca_model* model, const softdeca_avatar_mesh* mesh,
                                                        const softdeca_fit_options* options,
                                                        softdeca_avatar_fit** out_fit);
/* NULL is a no-op. */
SOFTDECA_API void softdeca_avatar_fit_destroy(softdeca_avatar_fit* fit);

/* Saves a fit: written whole to a new file of a unique name beside `path`, flushed and renamed
 * over it, so a reader sees the previous file or the new one, never a part, whichever threads
 * or processes save to the same path at once. On failure (SOFTDECA_ERROR_IO) the previous file
 * is left as it was and no temporary file remains. */
SOFTDECA_API softdeca_status softdeca_avatar_fit_save(const softdeca_avatar_fit* fit, const char* path);

/* Loads a saved fit for this model; refuses (SOFTDECA_ERROR_FORMAT) a fit of another bundle, a
 * file whose checksum does not match ("... is damaged (its checksum does not match); fit the
 * avatar again"), one of an earlier fit file version, and values no fit holds. */
SOFTDECA_API softdeca_status softdeca_avatar_fit_load(const softdeca_model* model, const char* path,
                                                      softdeca_avatar_fit** out_fit);

/* The fit's report as JSON (metres_per_unit, up_axis, shapes_matched, shapes_carried,
 * face_vertices, face_residual_mm_mean / _max, face_coverage, avatar_to_template_mm_median /
 * _p90, template_scale, quality: {passed, failed_measure, reason, bounds}, seconds, ...;
 * docs/avatars.md): NUL-terminated into buffer when
 * capacity suffices; *out_length (may be NULL) receives the length without the NUL either way
 * (SOFTDECA_ERROR_BUFFER_TOO_SMALL when it does not fit). */
SOFTDECA_API softdeca_status softdeca_avatar_fit_get_report(const softdeca_avatar_fit* fit, char* buffer,
                                                        uint32_t capacity, uint32_t* out_length);

/* The registered template skin (skin_vertex_count points) in the avatar's units and axes, and
 * the vertex count of the avatar the fit was made for; either output may be NULL. */
SOFTDECA_API softdeca_status softdeca_avatar_fit_get_registered(const softdeca_avatar_fit* fit, float* out_points,
                                                                uint32_t point_capacity, uint32_t* out_vertex_count);


/* ---- Geometry -------------------------------------------------------------------------- */

/* Embeds points in a tetrahedral mesh: for every point, the tetrahedron that contains it and
 * its four barycentric coordinates (which sum to one and reproduce the point exactly).
 * A point outside every tetrahedron gets the nearest one, with coordinates extrapolated
 * (some negative); `out_outside` then holds its distance to that tetrahedron, else 0.
 * This is how the skin surface S rides inside the layered head model's outer tet layer.
 *
 *   vertices        vertex_count * 3 floats
 *   tets            tet_count * 4 vertex indices, positively oriented
 *   points          point_count * 3 floats
 *   out_tet         point_count indices into tets
 *   out_barycentric point_count * 4 floats
 *   out_outside     point_count floats (metres), may be NULL
 */
SOFTDECA_API softdeca_status softdeca_embed_points(
    const float* vertices, uint32_t vertex_count, const int32_t* tets, uint32_t tet_count,
    const float* points, uint32_t point_count, int32_t* out_tet, float* out_barycentric,
    float* out_outside);

/* Signed volumes of tetrahedra (positive for the orientation of the layered head model;
 * (b-a) . ((c-a) x (d-a)) / 6). out_volumes holds tet_count floats. */
SOFTDECA_API softdeca_status softdeca_compute_tet_volumes(
    const float* vertices, uint32_t vertex_count, const int32_t* tets, uint32_t tet_count,
    float* out_volumes);


/* ---- Physics simulator phi† (projective dynamics over a layered head) ------------------- */
/*
 * The physics model of the paper (sections 3.2, 3.3, 3.6.1): an anatomical projective-dynamics
 * simulation over a simulation mesh whose unknowns are the simulated vertices (skin, muscle and
 * skull wraps, skull, eyes) and whose output skin S rides in the outer tet layer through a fixed
 * barycentric embedding. Soft Dirichlet targets on S (and landmarks, SparseSoftDECA) drive it.
 * The material parameters p are the list of plugin/data/parameters.json, compiled in:
 * enumerate it with softdeca_sim_get_parameter_count / softdeca_sim_get_parameter_info.
 * Arrays are packed row by row.
 */

typedef struct softdeca_sim softdeca_sim; /* opaque */

typedef struct softdeca_parameter_info {
  uint32_t struct_size;
  const char* name;        /* e.g. "w_soft_volume" (static string) */
  const char* unit;        /* "kPa", "g", "deg" or "" */
  const char* domain;      /* "global" or the element kind of per-element values: "soft_tet",
                              "muscle_tet", "connecting_tet", "skin_triangle", "skull_triangle",
                              "vertex", "skin_point", "landmark" */
  const char* description;
  double default_value, minimum, maximum; /* the closed range [minimum, maximum] */
  softdeca_bool log_scale;                /* sample uniformly in log space */
} softdeca_parameter_info;

SOFTDECA_API softdeca_status softdeca_sim_get_parameter_count(uint32_t* out_count);
SOFTDECA_API softdeca_status softdeca_sim_get_parameter_info(uint32_t index, softdeca_parameter_info* out_info);
/* Index of a simulator parameter by name; SOFTDECA_ERROR_INVALID_ARGUMENT if there is none. */
SOFTDECA_API softdeca_status softdeca_sim_find_parameter(const char* name, uint32_t* out_index);
/* plugin/data/parameters.json as compiled in (static string, never freed). */
SOFTDECA_API softdeca_status softdeca_sim_get_parameters_json(const char** out_json);

/* One side of a lip or teeth collision: skin points that must stay on the outer side of an
 * oriented surface (normals by the right-hand rule point to where the points belong). */
typedef struct softdeca_sim_collision_set {
  uint32_t struct_size;
  const int32_t* points;      /* point_count skin point indices */
  uint32_t point_count;
  const int32_t* surface;     /* surface_triangle_count * 3 indices */
  uint32_t surface_triangle_count;
  softdeca_bool surface_on_skin; /* true: indices of skin points; false: of simulated vertices (teeth) */
  float max_distance;         /* metres: farther closest points are not this contact */
} softdeca_sim_collision_set;

typedef struct softdeca_sim_mesh {
  uint32_t struct_size;
  const float* vertices;            /* vertex_count * 3: simulated vertices at rest (metres) */
  uint32_t vertex_count;
  const int32_t* soft_tets;         /* soft tissue, positively oriented, 4 each */
  uint32_t soft_tet_count;
  const int32_t* muscle_tets;       /* muscle tissue, positively oriented */
  uint32_t muscle_tet_count;
  const int32_t* connecting_tets;   /* skull to muscle, eyes to skull (any orientation) */
  uint32_t connecting_tet_count;
  const int32_t* skull_triangles;   /* skull surface: strain and bending, 3 each */
  uint32_t skull_triangle_count;
  const int32_t* cranium_vertices;  /* rigid bones; disjoint */
  uint32_t cranium_vertex_count;
  const int32_t* jaw_vertices;
  uint32_t jaw_vertex_count;
  softdeca_bool cranium_pinned, jaw_pinned; /* follow the frame's transform exactly */
  const float* cranium_pivot;       /* 3 floats, centre of the cranium scale; NULL: centroid */
  const float* jaw_pivot;
  const int32_t* skin_vertices;     /* skin_count * 4 simulated vertices per skin point */
  const float* skin_weights;        /* skin_count * 4 weights summing to 1 (0 for unused) */
  uint32_t skin_count;
  const int32_t* skin_triangles;    /* S's triangles over skin points, 3 each */
  uint32_t skin_triangle_count;
  const int32_t* landmark_points;   /* landmark_count * 3 skin points (SparseSoftDECA) */
  const float* landmark_weights;    /* landmark_count * 3 barycentric weights */
  uint32_t landmark_count;
  const softdeca_sim_collision_set* collisions;
  uint32_t collision_count;
} softdeca_sim_mesh;

typedef struct softdeca_sim_settings {
  uint32_t struct_size;
  uint32_t max_iterations;     /* iteration cap per solve (default 300) */
  float tolerance;             /* converged when the RMS move of one step < tolerance * size */
  uint32_t anderson_window;    /* 0: plain projective dynamics (default 5) */
  uint32_t threads;            /* 0: all hardware threads (at most 1024) */
  softdeca_bool paper_strain_rule; /* true: rotation projection above eps (paper); false: nearest point */
  uint32_t collision_rounds;   /* 0: no collision resolution */
  float collision_weight;      /* kPa */
  float penetration_tolerance; /* metres */
} softdeca_sim_settings;

/* Fills the defaults (struct_size must be set). */
SOFTDECA_API softdeca_status softdeca_sim_settings_init(softdeca_sim_settings* settings);

/* Validates the mesh and creates a simulator with the default parameters. settings may be
 * NULL. The arrays are copied; the caller may free them afterwards. */
SOFTDECA_API softdeca_status softdeca_sim_create(const softdeca_sim_mesh* mesh,
                                                 const softdeca_sim_settings* settings,
                                                 softdeca_sim** out_sim);
/* NULL is a no-op. */
SOFTDECA_API void softdeca_sim_destroy(softdeca_sim* sim);

SOFTDECA_API softdeca_status softdeca_sim_get_vertex_count(const softdeca_sim* sim, uint32_t* out_count);
SOFTDECA_API softdeca_status softdeca_sim_get_skin_count(const softdeca_sim* sim, uint32_t* out_count);

/* Parameter `index` of the simulator's list (softdeca_sim_get_parameter_info; by name through
 * softdeca_sim_find_parameter) set to one value everywhere (out of range: INVALID_ARGUMENT, nothing
 * changes). */
SOFTDECA_API softdeca_status softdeca_sim_set_parameter(softdeca_sim* sim, uint32_t index, double value);
SOFTDECA_API softdeca_status softdeca_sim_get_parameter(const softdeca_sim* sim, uint32_t index,
                                                        double* out_value);
/* Per-element values: count must equal the element count of the parameter's domain. */
SOFTDECA_API softdeca_status softdeca_sim_set_parameter_field(softdeca_sim* sim, uint32_t index,
                                                              const float* values, uint32_t count);

typedef struct softdeca_sim_frame {
  uint32_t struct_size;
  const float* skin_targets;        /* skin_count * 3: the target expression S_t */
  uint32_t skin_count;
  const float* landmark_targets;    /* landmark_count * 3 (SparseSoftDECA) or NULL */
  uint32_t landmark_count;
  const float* cranium_transform;   /* 12 floats, 3x4 row-major rigid transform; NULL: identity */
  const float* jaw_transform;
  const float* warm_start;          /* vertex_count * 3 or NULL */
  uint32_t warm_start_count;
} softdeca_sim_frame;

typedef struct softdeca_sim_stats {
  uint32_t struct_size;
  uint32_t iterations;
  softdeca_bool converged;
  double relative_step;     /* last plain step's RMS move / rest bounding-box diagonal */
  double estimated_error;   /* relative_step / (1 - contraction): distance to the solution */
  double contraction;       /* measured contraction of a plain step on the slowest mode */
  double energy;            /* projective dynamics energy (J) */
  double target_rms;        /* RMS distance of S to its (blended) targets (m) */
  double local_seconds, global_seconds, factor_seconds, total_seconds;
  uint32_t penetrating_before, penetrating_after, contacts;
  /* What a frame's sanity check needs (docs/physics.md, "Sanity bounds"). */
  uint32_t inverted_elements;       /* soft and muscle tets with volume <= 0 at the end */
  double max_target_distance;       /* largest distance of a point of S to its (blended) target (m) */
  uint32_t collision_rounds;        /* contact rounds run */
  uint32_t rejected_collision_rounds; /* rounds that moved points beyond the penetration depth */
  double max_contact_gap;           /* largest distance between the two sides of a contact (m) */
  double max_contact_correction;    /* largest move of a point of S by the contact step (m) */
} softdeca_sim_stats;

/* One static frame T = phi†(S_t, p). stats may be NULL. On success the result replaces the
 * simulator's output (read it with softdeca_sim_get_vertices / _get_skin); on failure the
 * previous output stays. */
SOFTDECA_API softdeca_status softdeca_sim_solve_static(softdeca_sim* sim, const softdeca_sim_frame* frame,
                                                       softdeca_sim_stats* stats);
/* The next frame of a dynamic sequence (eq. 9); the first after a reset is the static solution. */
SOFTDECA_API softdeca_status softdeca_sim_step_dynamic(softdeca_sim* sim, const softdeca_sim_frame* frame,
                                                       softdeca_sim_stats* stats);
SOFTDECA_API softdeca_status softdeca_sim_reset_dynamics(softdeca_sim* sim);
/* frame_count static frames over one factorisation on all threads. out_skin receives
 * out_skin_count = frame_count * skin_count points (3 floats each); stats (frame_count
 * entries) may be NULL. The simulator's output becomes the last frame's. */
SOFTDECA_API softdeca_status softdeca_sim_solve_static_batch(softdeca_sim* sim, const softdeca_sim_frame* frames,
                                                             uint32_t frame_count, float* out_skin,
                                                             uint32_t out_skin_count, softdeca_sim_stats* stats);
/* The last result (rest before the first solve): vertex_count * 3 / skin_count * 3 floats. */
SOFTDECA_API softdeca_status softdeca_sim_get_vertices(const softdeca_sim* sim, float* out_vertices,
                                                       uint32_t vertex_count);
SOFTDECA_API softdeca_status softdeca_sim_get_skin(const softdeca_sim* sim, float* out_skin, uint32_t skin_count);

/* ==== Streaming and recorded takes =====================================================
 * Face frames arrive live over UDP (our protocol, docs/protocol.md; Epic's Live Link Face app;
 * iFacialMocap) or from recording files (docs/recording.md), and all come out as one canonical
 * frame: 52 weights in canonical ARKit order (softdeca_blendshape_get_name), poses and landmarks in
 * metres in ARKit's face-anchor frame.
 * The receiver's functions may be called from any thread, concurrently, except
 * softdeca_receiver_destroy, which must follow every other call on that receiver; a recorder or
 * player handle must be used by one thread at a time. */

#define SOFTDECA_BLENDSHAPE_COUNT 52
#define SOFTDECA_MAX_LANDMARKS 150     /* landmarks per frame (a profile names at most this many) */
#define SOFTDECA_ARKIT_VERTEX_COUNT 1220 /* vertices of ARKit's face mesh */

/* Canonical name of blendshape `index` ("browDownLeft" = 0 ... "tongueOut" = 51), or NULL when
 * index >= 52. Static strings. */
SOFTDECA_API const char* softdeca_blendshape_get_name(uint32_t index);

/* The canonical index of the ARKit blendshape a rig's own shape name denotes, or -1 in
 * *out_index: ARKit's names in any case, behind a prefix or namespace ("blendShape1.eyeBlinkLeft",
 * "AK_07_EyeBlinkLeft"), with the side as a suffix ("eyeBlink_L", "eyeBlink.R", "eyeBlinkL"),
 * in snake case ("mouth_smile_l"); a word after the name ("eyeBlinkLeft_corrective") means no
 * match. The one rule of the product for rigs' names (docs/avatars.md). */
SOFTDECA_API softdeca_status softdeca_blendshape_find_index(const char* name, int32_t* out_index);

typedef enum softdeca_tracking {
  SOFTDECA_TRACKING_LOST = 0,
  SOFTDECA_TRACKING_TRACKED = 1,
  SOFTDECA_TRACKING_LIMITED = 2
} softdeca_tracking;

/* softdeca_frame.flags */
#define SOFTDECA_FRAME_HAS_HEAD 1u     /* head pose present */
#define SOFTDECA_FRAME_HAS_EYES 2u     /* eye poses present */
#define SOFTDECA_FRAME_HAS_SEQUENCE 4u /* the sender numbers its datagrams (our protocol) */

/* A rigid pose: position in metres, rotation as a unit quaternion (x, y, z, w). */
typedef struct softdeca_pose {
  float position[3];
  float rotation[4];
} softdeca_pose;

typedef struct softdeca_frame {
  uint32_t struct_size;          /* sizeof(softdeca_frame) */
  uint32_t flags;         /* SOFTDECA_FRAME_HAS_* */
  uint32_t session_id;    /* the sender's stream */
  uint32_t sequence;      /* the sender's datagram number, with SOFTDECA_FRAME_HAS_SEQUENCE */
  int32_t tracking;       /* softdeca_tracking */
  uint32_t profile_id;    /* landmark profile naming the landmarks' vertices; 0: none */
  double capture_time;    /* seconds, sender's clock (ARKit timestamp, or timecode since midnight) */
  double send_time;       /* seconds, sender's clock; 0: unknown */
  double receive_time;    /* seconds, this host's monotonic clock; 0: not received live */
  float weights[SOFTDECA_BLENDSHAPE_COUNT]; /* [0, 1], canonical ARKit order */
  softdeca_pose head;      /* the face anchor's pose in ARKit's world frame */
  softdeca_pose left_eye;  /* relative to the face anchor */
  softdeca_pose right_eye;
  uint32_t landmark_count;
  uint32_t reserved;
  float landmarks[SOFTDECA_MAX_LANDMARKS * 3]; /* xyz per landmark, face-anchor frame */
} softdeca_frame;

/* ---- Receiver: a background thread reading one UDP port --------------------------------- */

typedef enum softdeca_stream_format {
  SOFTDECA_FORMAT_AUTO = 0,         /* recognise each datagram's format */
  SOFTDECA_FORMAT_SOFTDECA = 1,     /* ours (default port 50110) */
  SOFTDECA_FORMAT_LIVELINKFACE = 2, /* Live Link Face UDP, version 6 (default port 11111) */
  SOFTDECA_FORMAT_IFACIALMOCAP = 3  /* iFacialMocap text (default port 49983) */
} softdeca_stream_format;

typedef struct softdeca_receiver_config {
  uint32_t struct_size;
  int32_t format;           /* softdeca_stream_format */
  const char* bind_address; /* numeric IPv4 or IPv6 address; NULL: "127.0.0.1" (loopback), or
                             * "0.0.0.0" (all IPv4) with listen_network */
  uint32_t port;            /* 0: any free port (softdeca_receiver_get_port tells which) */
  uint32_t queue_capacity;  /* delivered frames kept for softdeca_receiver_get_next, 1 to 65536 */
  double jitter_delay;      /* seconds in [0, 5] that frames wait to be put in order; 0: none */
  /* Security (docs/security.md). */
  softdeca_bool listen_network; /* 1: may bind a network address; 0: loopback addresses only */
  softdeca_bool follow_newest;  /* 1: a new sender takes the session at once; 0: the first
                                 * sender holds it until quiet for session_hold seconds */
  double session_hold;      /* seconds in (0, 3600]; 0: 2 */
  double source_rate_limit; /* datagrams per second per sender; 0: 1000; negative: no limit */
} softdeca_receiver_config;

/* Fills a config with the defaults: auto format, 127.0.0.1:50110, 256 frames, no delay, the
 * first sender holds the session for 2 s of quiet, 1000 datagrams per second per sender. */
SOFTDECA_API softdeca_status softdeca_receiver_config_init(softdeca_receiver_config* config);

typedef struct softdeca_receiver softdeca_receiver;

/* Binds the socket and starts the thread (SOFTDECA_ERROR_IO when the port is taken). */
SOFTDECA_API softdeca_status softdeca_receiver_create(const softdeca_receiver_config* config,
                                                      softdeca_receiver** out_receiver);
/* Stops the thread and frees the receiver (and ends its recording). NULL is ignored. */
SOFTDECA_API void softdeca_receiver_destroy(softdeca_receiver* receiver);
SOFTDECA_API softdeca_status softdeca_receiver_get_port(const softdeca_receiver* receiver,
                                                    uint32_t* out_port);
/* The oldest delivered frame not yet taken, waiting up to `timeout` seconds (0: do not wait).
 * *out_received is true when a frame was written, else false. */
SOFTDECA_API softdeca_status softdeca_receiver_get_next(softdeca_receiver* receiver, double timeout,
                                                    softdeca_frame* out_frame,
                                                    softdeca_bool* out_received);
/* The newest delivered frame, taken or not (what an avatar shows now). */
SOFTDECA_API softdeca_status softdeca_receiver_get_latest(const softdeca_receiver* receiver,
                                                      softdeca_frame* out_frame,
                                                      softdeca_bool* out_received);

typedef struct softdeca_receiver_stats {
  uint32_t struct_size;
  uint32_t reserved;
  uint64_t datagrams;        /* read from the socket */
  uint64_t frames;           /* well-formed frames */
  uint64_t control_messages; /* well-formed profile, neutral and request messages */
  uint64_t delivered;        /* frames out of the jitter buffer */
  uint64_t malformed;        /* dropped as malformed: the sum of the six below */
  uint64_t undersized;
  uint64_t oversized;
  uint64_t bad_magic;
  uint64_t incompatible_version;
  uint64_t bad_length;       /* a length or count that disagrees with the datagram */
  uint64_t bad_value;        /* NaN, out-of-range index, mismatching id */
  uint64_t unknown_type;     /* messages of a newer protocol minor version: ignored */
  uint64_t duplicates;       /* dropped */
  uint64_t reordered;        /* arrived after a newer datagram */
  uint64_t late;             /* dropped: a newer frame had already been delivered */
  uint64_t lost;             /* sequence numbers never received */
  uint64_t expected;         /* sequence numbers the senders used */
  uint64_t overflowed;       /* delivered frames dropped because nobody took them */
  uint64_t session_changes;
  uint64_t clock_resyncs;    /* the sender's capture clock jumped */
  uint64_t requests_sent;    /* profile or neutral requests sent to the sender */
  double frame_rate_hz;      /* delivered frames per second over the last ~2 s */
  double loss_ratio;         /* lost / expected */
  double latency_p50_ms;     /* arrival at the socket -> frame available, recent frames */
  double latency_p99_ms;
  uint64_t foreign;           /* dropped: another sender held the session */
  uint64_t rate_limited;      /* dropped: over the per-sender rate limit */
  uint64_t recording_dropped; /* frames the recording's disk could not keep up with */
} softdeca_receiver_stats;

SOFTDECA_API softdeca_status softdeca_receiver_get_stats(const softdeca_receiver* receiver,
                                                         softdeca_receiver_stats* out_stats);
/* The landmark profile of the newest landmark frames (else the newest profile received):
 * its id and ARKit vertex indices. *out_count is always set to the profile's size (0 and id 0
 * when there is none yet); SOFTDECA_ERROR_BUFFER_TOO_SMALL when capacity is smaller. */
SOFTDECA_API softdeca_status softdeca_receiver_get_profile(const softdeca_receiver* receiver,
                                                       uint32_t* out_id, int32_t* out_indices,
                                                       uint32_t capacity, uint32_t* out_count);
/* The sender's neutral face mesh (calibration), xyz per vertex; *out_vertex_count as above. */
SOFTDECA_API softdeca_status softdeca_receiver_get_neutral(const softdeca_receiver* receiver,
                                                       float* out_xyz, uint32_t vertex_capacity,
                                                       uint32_t* out_vertex_count);
/* Asks the current sender (our protocol) for its neutral mesh; *out_sent false without a sender. */
SOFTDECA_API softdeca_status softdeca_receiver_request_neutral(softdeca_receiver* receiver,
                                                               softdeca_bool* out_sent);

/* ---- Recordings ----------------------------------------------------------------------------- */

typedef struct softdeca_recording_header {
  uint32_t struct_size;
  uint32_t reserved;
  const char* device;     /* capturing device or app; NULL: "" */
  const char* subject;    /* performer or take; NULL: "" */
  const char* source;     /* where frames come from; NULL: "" */
  double start_unix_time; /* seconds since 1970-01-01 UTC; 0: unknown */
  double timecode_rate;   /* frames per second of a timecode clock; 0: none */
} softdeca_recording_header;

/* Records every frame the receiver delivers from now on into a new file at `path`, with the
 * profiles and neutral meshes the stream carries. `path` must be a regular file (or not exist):
 * a FIFO or a folder is SOFTDECA_ERROR_INVALID_ARGUMENT at once. */
SOFTDECA_API softdeca_status softdeca_receiver_start_recording(
    softdeca_receiver* receiver, const char* path, const softdeca_recording_header* header);
/* Ends the recording; *out_frames (may be NULL) gets the frames written. SOFTDECA_ERROR_IO when
 * a write failed on the way (the file then holds every frame before the failure). */
SOFTDECA_API softdeca_status softdeca_receiver_stop_recording(softdeca_receiver* receiver,
                                                              uint32_t* out_frames);

typedef struct softdeca_recorder softdeca_recorder;

/* Creates (replaces) a recording file and writes its header; SOFTDECA_ERROR_INVALID_ARGUMENT
 * when `path` names something other than a regular file (a FIFO, a folder). */
SOFTDECA_API softdeca_status softdeca_recorder_create(const char* path,
                                                      const softdeca_recording_header* header,
                                                      softdeca_recorder** out_recorder);
/* Appends a frame; each is flushed to the operating system at once. */
SOFTDECA_API softdeca_status softdeca_recorder_write(softdeca_recorder* recorder,
                                                     const softdeca_frame* frame);
/* Appends a landmark profile (name may be NULL) and returns its id for frames to name. */
SOFTDECA_API softdeca_status softdeca_recorder_write_profile(softdeca_recorder* recorder,
                                                             const char* name,
                                                             const int32_t* indices, uint32_t count,
                                                             uint32_t* out_id);
SOFTDECA_API softdeca_status softdeca_recorder_write_neutral(softdeca_recorder* recorder,
                                                             const float* xyz,
                                                             uint32_t vertex_count);
/* Closes the file. NULL is ignored. */
SOFTDECA_API void softdeca_recorder_destroy(softdeca_recorder* recorder);

typedef struct softdeca_recording_info {
  uint32_t struct_size;
  uint32_t frame_count;
  double duration;         /* seconds from the first to the last frame */
  double start_unix_time;
  double timecode_rate;
  uint32_t damaged_regions; /* stretches of the file skipped as damaged */
  uint32_t truncated_bytes; /* an incomplete record at the end (a cut-off write) */
  char device[64];          /* NUL-terminated, cut to 63 bytes */
  char subject[64];
  char source[64];
} softdeca_recording_info;

typedef struct softdeca_player softdeca_player;

/* Opens a recording, recovering what a damaged file still holds (info tells what was lost).
 * Frames stay in the file and are read as they are asked for; weights come out in [0, 1]
 * (docs/recording.md, "Values"). SOFTDECA_ERROR_FORMAT when its header is unreadable, it has
 * no frame or it is over 1 GiB; SOFTDECA_ERROR_INVALID_ARGUMENT when `path` is not a regular
 * file (a FIFO, a folder: refused without blocking). */
SOFTDECA_API softdeca_status softdeca_player_load(const char* path, softdeca_player** out_player);
/* NULL is ignored. */
SOFTDECA_API void softdeca_player_destroy(softdeca_player* player);
SOFTDECA_API softdeca_status softdeca_player_get_info(const softdeca_player* player,
                                                  softdeca_recording_info* out_info);
/* Frame `index` as recorded (frames sorted by capture time). */
SOFTDECA_API softdeca_status softdeca_player_get_frame(const softdeca_player* player, uint32_t index,
                                                   softdeca_frame* out_frame);
/* The frame `time` seconds after the first (clamped to the recording), interpolated. */
SOFTDECA_API softdeca_status softdeca_player_get_frame_at(const softdeca_player* player, double time,
                                                      softdeca_frame* out_frame);
SOFTDECA_API softdeca_status softdeca_player_seek(softdeca_player* player, double time);
/* Playback speed in [0, 1000]; 1 is real time, 0 pauses. */
SOFTDECA_API softdeca_status softdeca_player_set_speed(softdeca_player* player, double speed);
SOFTDECA_API softdeca_status softdeca_player_set_loop(softdeca_player* player, softdeca_bool loop);
/* Moves the playhead by dt * speed seconds (wrapping when looping) and returns the frame there;
 * *out_ended (may be NULL) is true when playback reached the end without looping. */
SOFTDECA_API softdeca_status softdeca_player_advance(softdeca_player* player, double dt,
                                                     softdeca_frame* out_frame,
                                                     softdeca_bool* out_ended);
SOFTDECA_API softdeca_status softdeca_player_get_position(const softdeca_player* player,
                                                      double* out_time);
/* The recording's newest landmark profile and neutral mesh, as for the receiver. */
SOFTDECA_API softdeca_status softdeca_player_get_profile(const softdeca_player* player,
                                                     uint32_t* out_id, int32_t* out_indices,
                                                     uint32_t capacity, uint32_t* out_count);
SOFTDECA_API softdeca_status softdeca_player_get_neutral(const softdeca_player* player,
                                                     float* out_xyz, uint32_t vertex_capacity,
                                                     uint32_t* out_vertex_count);

/* ---- Live Link Face CSV takes --------------------------------------------------------------- */

typedef struct softdeca_convert_report {
  uint32_t struct_size;
  uint32_t frames;         /* frames written */
  uint32_t rows;           /* CSV data rows read (CSV -> recording) */
  uint32_t face_lost_rows; /* rows where the app had lost the face: skipped */
  uint32_t malformed_rows; /* rows that did not parse: skipped */
} softdeca_convert_report;

/* A Live Link Face CSV take into a recording. Columns are found by name; timecode_rate is the
 * take's timecode clock (0: the app's default, 60). out_report may be NULL. */
SOFTDECA_API softdeca_status softdeca_convert_livelinkface_csv(const char* csv_path,
                                                               const char* recording_path,
                                                               double timecode_rate,
                                                               softdeca_convert_report* out_report);
/* A recording into a Live Link Face CSV take; timecode_rate 0: the recording's, else 60. */
SOFTDECA_API softdeca_status softdeca_export_livelinkface_csv(const char* recording_path,
                                                              const char* csv_path,
                                                              double timecode_rate,
                                                              softdeca_convert_report* out_report);
/* ==== end of streaming and recorded takes ================================================= */

#ifdef __cplusplus
}
#endif
#endif /* SOFTDECA_SOFTDECA_H */
