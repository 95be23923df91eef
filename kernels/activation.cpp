#include "kernels/activation.h"

#include <cstring>
#include <stdexcept>
#include <string>

namespace ampi {

static const char* const kNames[] = {"none",        "relu",    "relu6",     "hardswish", "hardsigmoid",
                                     "sigmoid",     "leakyrelu", "elu",     "tanh",
                                     "gelu"};

const char* activation_name(Activation a) { return kNames[static_cast<int>(a)]; }

Activation parse_activation(const char* name) {
  for (int i = 0; i < static_cast<int>(sizeof(kNames) / sizeof(kNames[0])); ++i)
    if (std::strcmp(name, kNames[i]) == 0) return static_cast<Activation>(i);
  throw std::invalid_argument(std::string("unknown activation '") + name + "'");
}

}  // namespace ampi
