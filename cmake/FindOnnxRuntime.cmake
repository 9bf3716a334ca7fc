# Imported target onnxruntime::onnxruntime from ONNXRUNTIME_ROOT, which has the layout of
# ONNX Runtime's release archives (include/onnxruntime_c_api.h, lib/libonnxruntime.*).
# `make setup` assembles such a root in .deps/onnxruntime on Debian.
find_path(ONNXRUNTIME_INCLUDE_DIR onnxruntime_c_api.h
  PATHS "${ONNXRUNTIME_ROOT}/include" "${ONNXRUNTIME_ROOT}/include/onnxruntime" NO_DEFAULT_PATH)
if(WIN32 AND NOT MSVC)
  # MinGW: the Windows package has onnxruntime.dll but no import library; GNU ld links the DLL.
  find_file(ONNXRUNTIME_LIBRARY onnxruntime.dll PATHS "${ONNXRUNTIME_ROOT}/lib" NO_DEFAULT_PATH)
else()
  find_library(ONNXRUNTIME_LIBRARY onnxruntime PATHS "${ONNXRUNTIME_ROOT}/lib" NO_DEFAULT_PATH)
endif()
if(ONNXRUNTIME_INCLUDE_DIR AND ONNXRUNTIME_LIBRARY)
  add_library(onnxruntime::onnxruntime UNKNOWN IMPORTED)
  set_target_properties(onnxruntime::onnxruntime PROPERTIES
    IMPORTED_LOCATION "${ONNXRUNTIME_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${ONNXRUNTIME_INCLUDE_DIR}")
  if(MINGW)
    # The header's Windows branch uses MSVC spellings MinGW's headers do not define.
    set_property(TARGET onnxruntime::onnxruntime APPEND PROPERTY INTERFACE_COMPILE_OPTIONS "-D_Return_type_success_(x)="
                 "-D_stdcall=__stdcall")
  endif()
  set(OnnxRuntime_FOUND TRUE)
  message(STATUS "ONNX Runtime: ${ONNXRUNTIME_LIBRARY}")
else()
  message(FATAL_ERROR "ONNX Runtime not found under ONNXRUNTIME_ROOT='${ONNXRUNTIME_ROOT}'. "
                      "Run `make setup` or pass -DONNXRUNTIME_ROOT=<release archive folder>.")
endif()
