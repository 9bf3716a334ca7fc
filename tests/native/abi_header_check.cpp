// The header check of abi_header_check.c, compiled as C++.
#include "abi_header_check.c"
