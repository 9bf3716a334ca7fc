# Imported target onnxruntime::onnxruntime from ONNXRUNTIME_ROOT, which has the layout of
# ONNX Runtime's release archives (include/onnxruntime_c_api.h, lib/libonnxruntime.*).
# `make setup` assembles such a root in .deps/onnxruntime on Debian.
find_path(ONNXRUNTIME_INCLUDE_DIR onnxruntime_c_api.h
  PATHS "${ONNXRUNTIME_ROOT}/include" "${ONNXRUNTIME_ROOT}/include/onnxruntime" NO_DEFAULT_PATH)
find_library(ONNXRUNTIME_LIBRARY onnxruntime PATHS "${ONNXRUNTIME_ROOT}/lib" NO_DEFAULT_PATH)
if(ONNXRUNTIME_INCLUDE_DIR AND ONNXRUNTIME_LIBRARY)
  add_library(onnxruntime::onnxruntime SHARED IMPORTED)
  set_target_properties(onnxruntime::onnxruntime PROPERTIES
    IMPORTED_LOCATION "${ONNXRUNTIME_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${ONNXRUNTIME_INCLUDE_DIR}")
  set(OnnxRuntime_FOUND TRUE)
  message(STATUS "ONNX Runtime: ${ONNXRUNTIME_LIBRARY}")
else()
  message(FATAL_ERROR "ONNX Runtime not found under ONNXRUNTIME_ROOT='${ONNXRUNTIME_ROOT}'. "
                      "Run `make setup` or pass -DONNXRUNTIME_ROOT=<release archive folder>.")
endif()
