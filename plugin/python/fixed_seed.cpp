// softdeca_fixed_seed: preloaded (LD_PRELOAD) into the process that runs fTetWild's fill, so the
// tet mesh of a head depends on its input surface only.
//
// fTetWild seeds its generator from std::random_device, so the same surface gave meshes of 5,000
// to 5,600 vertices from run to run and machine to machine, and every test or dataset built on a
// head saw another mesh. Defining random_device's draw here interposes libstdc++'s: the fill then
// draws the same sequence of seeds in every fresh process. Nothing else is loaded with it.
#include <random>

namespace std {
unsigned int random_device::_M_getval() {
  // A fixed sequence (Knuth's multiplicative hash of a counter), not one constant, so code that
  // draws several seeds still gets distinct ones. Only the fill's single-threaded process uses it.
  static unsigned int counter = 0;
  return ++counter * 2654435761u;
}
}  // namespace std
