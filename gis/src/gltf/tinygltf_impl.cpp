// SPDX-License-Identifier: MIT
// tinygltf's implementation, compiled here rather than taken from Debian's libtinygltf.so: that
// build links stb_image and decodes every image it meets (a needless attack surface: we need
// geometry only). Here images are neither read from disk nor decoded (issue 6).
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#if defined(__GNUC__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <tiny_gltf.h>
