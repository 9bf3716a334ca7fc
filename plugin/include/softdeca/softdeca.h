/*
 * SoftDECA native library: the public C ABI.
 *
 * This header is the only way into the library, from Unity (P/Invoke), Python or the CLI.
 * Conventions that hold for every function:
 *   - Units are metres; the frame is right-handed, +Y up, +Z out of the face (ARKit's
 *     face-anchor frame). Arrays of 3D points are packed xyz floats.
 *   - Every function returns a softdeca_status. On failure the reason is available from
 *     softdeca_last_error() on the same thread, and output buffers are left untouched.
 *   - Every array argument comes with its element count; null pointers, wrong sizes and
 *     non-finite values are rejected with a status, never with a crash or an exception.
 *   - The library keeps no global mutable state (the last-error text is thread-local).
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
  SOFTDECA_ERROR_INTERNAL = 6          /* unexpected failure inside the library          */
} softdeca_status;

/* Library version as "MAJOR.MINOR.PATCH". The pointer is static and never freed. */
SOFTDECA_API const char* softdeca_version(void);

/* Text describing the last failure of a softdeca_* call on the calling thread ("" if none).
 * Valid until the next softdeca_* call on this thread. */
SOFTDECA_API const char* softdeca_last_error(void);

/* Human-readable name of a status code (static string). */
SOFTDECA_API const char* softdeca_status_name(softdeca_status status);

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
    const float* vertices, size_t vertex_count, const int32_t* tets, size_t tet_count,
    const float* points, size_t point_count, int32_t* out_tet, float* out_barycentric,
    float* out_outside);

/* Signed volumes of tetrahedra (positive for the orientation of the layered head model;
 * (b-a) . ((c-a) x (d-a)) / 6). out_volumes holds tet_count floats. */
SOFTDECA_API softdeca_status softdeca_tet_volumes(
    const float* vertices, size_t vertex_count, const int32_t* tets, size_t tet_count,
    float* out_volumes);


/* ---- Physics simulator phi† (projective dynamics over a layered head) ------------------- */
/*
 * The physics model of the paper (sections 3.2, 3.3, 3.6.1): an anatomical projective-dynamics
 * simulation over a simulation mesh whose unknowns are the simulated vertices (skin, muscle and
 * skull wraps, skull, eyes) and whose output skin S rides in the outer tet layer through a fixed
 * barycentric embedding. Soft Dirichlet targets on S (and landmarks, SparseSoftDECA) drive it.
 * The material parameters p are the list of plugin/data/parameters.json, compiled in:
 * enumerate it with softdeca_parameter_count / softdeca_parameter_get_info.
 *
 * Structs carry their own size (struct_size = sizeof(struct)) for forward compatibility: the
 * library refuses a struct_size smaller than the version it knows and ignores trailing fields
 * it does not know. Arrays are packed row by row; index arrays are int32.
 */

typedef struct softdeca_sim softdeca_sim; /* opaque */

typedef struct softdeca_parameter_info {
  size_t struct_size;
  const char* name;        /* e.g. "w_soft_volume" (static string) */
  const char* unit;        /* "kPa", "g", "deg" or "" */
  const char* domain;      /* "global" or the element kind of per-element values: "soft_tet",
                              "muscle_tet", "connecting_tet", "skin_triangle", "skull_triangle",
                              "vertex", "skin_point", "landmark" */
  const char* description;
  double default_value, lo, hi; /* closed range */
  int32_t log_scale;            /* 1: sample uniformly in log space */
} softdeca_parameter_info;

SOFTDECA_API softdeca_status softdeca_parameter_count(size_t* out_count);
SOFTDECA_API softdeca_status softdeca_parameter_get_info(size_t index, softdeca_parameter_info* out_info);
/* plugin/data/parameters.json as compiled in (static string, never freed). */
SOFTDECA_API softdeca_status softdeca_parameters_json(const char** out_json);

/* One side of a lip or teeth collision: skin points that must stay on the outer side of an
 * oriented surface (normals by the right-hand rule point to where the points belong). */
typedef struct softdeca_sim_collision_set {
  size_t struct_size;
  const int32_t* points;      /* point_count skin point indices */
  size_t point_count;
  const int32_t* surface;     /* surface_triangle_count * 3 indices */
  size_t surface_triangle_count;
  int32_t surface_on_skin;    /* 1: indices of skin points; 0: of simulated vertices (teeth) */
  float max_distance;         /* metres: farther closest points are not this contact */
} softdeca_sim_collision_set;

typedef struct softdeca_sim_mesh {
  size_t struct_size;
  const float* vertices;            /* vertex_count * 3: simulated vertices at rest (metres) */
  size_t vertex_count;
  const int32_t* soft_tets;         /* soft tissue, positively oriented, 4 each */
  size_t soft_tet_count;
  const int32_t* muscle_tets;       /* muscle tissue, positively oriented */
  size_t muscle_tet_count;
  const int32_t* connecting_tets;   /* skull to muscle, eyes to skull (any orientation) */
  size_t connecting_tet_count;
  const int32_t* skull_triangles;   /* skull surface: strain and bending, 3 each */
  size_t skull_triangle_count;
  const int32_t* cranium_vertices;  /* rigid bones; disjoint */
  size_t cranium_vertex_count;
  const int32_t* jaw_vertices;
  size_t jaw_vertex_count;
  int32_t cranium_pinned, jaw_pinned; /* 1: follow the frame's transform exactly */
  const float* cranium_pivot;       /* 3 floats, centre of the cranium scale; NULL: centroid */
  const float* jaw_pivot;
  const int32_t* skin_vertices;     /* skin_count * 4 simulated vertices per skin point */
  const float* skin_weights;        /* skin_count * 4 weights summing to 1 (0 for unused) */
  size_t skin_count;
  const int32_t* skin_triangles;    /* S's triangles over skin points, 3 each */
  size_t skin_triangle_count;
  const int32_t* landmark_points;   /* landmark_count * 3 skin points (SparseSoftDECA) */
  const float* landmark_weights;    /* landmark_count * 3 barycentric weights */
  size_t landmark_count;
  const softdeca_sim_collision_set* collisions;
  size_t collision_count;
} softdeca_sim_mesh;

typedef struct softdeca_sim_settings {
  size_t struct_size;
  int32_t max_iterations;      /* iteration cap per solve (default 300) */
  float tolerance;             /* converged when the RMS move of one step < tolerance * size */
  int32_t anderson_window;     /* 0: plain projective dynamics (default 5) */
  int32_t threads;             /* 0: all hardware threads */
  int32_t paper_strain_rule;   /* 1: rotation projection above eps (paper); 0: nearest point */
  int32_t collision_rounds;    /* 0: no collision resolution */
  float collision_weight;      /* kPa */
  float penetration_tolerance; /* metres */
} softdeca_sim_settings;

/* Fills the defaults (struct_size must be set). */
SOFTDECA_API softdeca_status softdeca_sim_default_settings(softdeca_sim_settings* settings);

/* Validates the mesh and creates a simulator with the default parameters. settings may be
 * NULL. The arrays are copied; the caller may free them afterwards. */
SOFTDECA_API softdeca_status softdeca_sim_create(const softdeca_sim_mesh* mesh,
                                                 const softdeca_sim_settings* settings,
                                                 softdeca_sim** out_sim);
SOFTDECA_API void softdeca_sim_destroy(softdeca_sim* sim);

SOFTDECA_API softdeca_status softdeca_sim_vertex_count(const softdeca_sim* sim, size_t* out_count);
SOFTDECA_API softdeca_status softdeca_sim_skin_count(const softdeca_sim* sim, size_t* out_count);

/* Sets a parameter to one value everywhere (out of range: INVALID_ARGUMENT, nothing changes). */
SOFTDECA_API softdeca_status softdeca_sim_set_parameter(softdeca_sim* sim, const char* name, double value);
SOFTDECA_API softdeca_status softdeca_sim_get_parameter(const softdeca_sim* sim, const char* name,
                                                        double* out_value);
/* Per-element values: count must equal the element count of the parameter's domain. */
SOFTDECA_API softdeca_status softdeca_sim_set_parameter_field(softdeca_sim* sim, const char* name,
                                                              const float* values, size_t count);

typedef struct softdeca_sim_frame {
  size_t struct_size;
  const float* skin_targets;        /* skin_count * 3: the target expression S_t */
  size_t skin_count;
  const float* landmark_targets;    /* landmark_count * 3 (SparseSoftDECA) or NULL */
  size_t landmark_count;
  const float* cranium_transform;   /* 12 floats, 3x4 row-major rigid transform; NULL: identity */
  const float* jaw_transform;
  const float* warm_start;          /* vertex_count * 3 or NULL */
  size_t warm_start_count;
} softdeca_sim_frame;

typedef struct softdeca_sim_stats {
  size_t struct_size;
  int32_t iterations;
  int32_t converged;
  double relative_step;     /* last plain step's RMS move / rest bounding-box diagonal */
  double estimated_error;   /* relative_step / (1 - contraction): distance to the solution */
  double contraction;       /* measured contraction of a plain step on the slowest mode */
  double energy;            /* projective dynamics energy (J) */
  double target_rms;        /* RMS distance of S to its (blended) targets (m) */
  double local_seconds, global_seconds, factor_seconds, total_seconds;
  int32_t penetrating_before, penetrating_after, contacts;
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
                                                             size_t frame_count, float* out_skin,
                                                             size_t out_skin_count, softdeca_sim_stats* stats);
/* The last result (rest before the first solve): vertex_count * 3 / skin_count * 3 floats. */
SOFTDECA_API softdeca_status softdeca_sim_get_vertices(const softdeca_sim* sim, float* out_vertices,
                                                       size_t vertex_count);
SOFTDECA_API softdeca_status softdeca_sim_get_skin(const softdeca_sim* sim, float* out_skin, size_t skin_count);

#ifdef __cplusplus
}
#endif
#endif /* SOFTDECA_SOFTDECA_H */
