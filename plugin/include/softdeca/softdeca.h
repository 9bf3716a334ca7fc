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

#ifdef __cplusplus
}
#endif
#endif /* SOFTDECA_SOFTDECA_H */
