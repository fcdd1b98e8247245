// tinygltf's implementation, once, in the configuration importers/tinygltf.hpp sets.
#define TINYGLTF_IMPLEMENTATION
#include "importers/tinygltf.hpp"
