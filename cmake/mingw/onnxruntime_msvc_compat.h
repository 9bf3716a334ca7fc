/* Force-included before ONNX Runtime's headers in MinGW builds (cmake/FindOnnxRuntime.cmake):
 * their Windows branch expects two things of MSVC that MinGW's headers lack. */
#pragma once
#ifndef _Return_type_success_
#define _Return_type_success_(expr)
#endif
#ifndef _stdcall
#define _stdcall __stdcall
#endif
