# Imported target onnxruntime::onnxruntime from ONNXRUNTIME_ROOT, which has the layout of
# ONNX Runtime's release archives (include/onnxruntime_c_api.h, lib/libonnxruntime.*).
# `make setup` assembles such a root in .deps/onnxruntime on Debian. For Windows a root with
# lib/onnxruntime.dll and no import library serves too (MinGW's ld links against the DLL itself;
# `make windows` assembles .deps/onnxruntime-win so).
find_path(ONNXRUNTIME_INCLUDE_DIR onnxruntime_c_api.h
  PATHS "${ONNXRUNTIME_ROOT}/include" "${ONNXRUNTIME_ROOT}/include/onnxruntime" NO_DEFAULT_PATH NO_CMAKE_FIND_ROOT_PATH)
find_library(ONNXRUNTIME_LIBRARY onnxruntime PATHS "${ONNXRUNTIME_ROOT}/lib" NO_DEFAULT_PATH NO_CMAKE_FIND_ROOT_PATH)
if(WIN32)
  find_file(ONNXRUNTIME_DLL onnxruntime.dll PATHS "${ONNXRUNTIME_ROOT}/lib" "${ONNXRUNTIME_ROOT}/bin"
            NO_DEFAULT_PATH NO_CMAKE_FIND_ROOT_PATH)
  if(NOT ONNXRUNTIME_LIBRARY AND ONNXRUNTIME_DLL AND NOT MSVC)
    set(ONNXRUNTIME_LIBRARY "${ONNXRUNTIME_DLL}")
  endif()
endif()
if(ONNXRUNTIME_INCLUDE_DIR AND ONNXRUNTIME_LIBRARY)
  add_library(onnxruntime::onnxruntime SHARED IMPORTED)
  set_target_properties(onnxruntime::onnxruntime PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${ONNXRUNTIME_INCLUDE_DIR}")
  if(WIN32)
    # The import library (or, with MinGW, the DLL) is what links; the DLL is what runs.
    set_target_properties(onnxruntime::onnxruntime PROPERTIES IMPORTED_IMPLIB "${ONNXRUNTIME_LIBRARY}"
                          IMPORTED_LOCATION "${ONNXRUNTIME_DLL}")
    if(MINGW)
      # The headers' Windows branch expects MSVC (a SAL annotation, _stdcall): a shim is force-included.
      set_target_properties(onnxruntime::onnxruntime PROPERTIES
        INTERFACE_COMPILE_OPTIONS "SHELL:-include ${CMAKE_CURRENT_LIST_DIR}/mingw/onnxruntime_msvc_compat.h")
    endif()
  else()
    set_target_properties(onnxruntime::onnxruntime PROPERTIES IMPORTED_LOCATION "${ONNXRUNTIME_LIBRARY}")
  endif()
  set(OnnxRuntime_FOUND TRUE)
  message(STATUS "ONNX Runtime: ${ONNXRUNTIME_LIBRARY}")
else()
  message(FATAL_ERROR "ONNX Runtime not found under ONNXRUNTIME_ROOT='${ONNXRUNTIME_ROOT}'. "
                      "Run `make setup` or pass -DONNXRUNTIME_ROOT=<release archive folder>.")
endif()
