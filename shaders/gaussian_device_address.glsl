// The buffers that a splat count can grow past one storage binding's range (the shape and SH
// words, the projected records; GaussianGeometryAddresses in GaussianSplatProjectionContract.h),
// reached through device addresses (bufferDeviceAddress, shaderInt64). A record's address is a
// 64-bit sum of the buffer's address and index * stride, so neither an index nor a byte
// offset wraps at 32 bits. Included after the contract header; the including shader enables
// GL_EXT_buffer_reference and GL_EXT_shader_explicit_arithmetic_types_int64 first.
#ifndef OPEN3D_GAUSSIAN_DEVICE_ADDRESS_GLSL
#define OPEN3D_GAUSSIAN_DEVICE_ADDRESS_GLSL

uint64_t DeviceAddress(uint lo, uint hi) { return packUint2x32(uvec2(lo, hi)); }

// Address of record `index` of `stride` bytes in the buffer at `base`.
uint64_t RecordAddress(uint64_t base, uint index, uint stride) {
    return base + uint64_t(index) * uint64_t(stride);
}

// One projected record (64 bytes, 16-byte aligned: read and written as four 128-bit words).
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer ProjectedIn {
    GaussianProjectedWords words;
};
layout(buffer_reference, std430, buffer_reference_align = 16) writeonly buffer ProjectedOut {
    GaussianProjectedWords words;
};

GaussianProjectedSplat LoadProjected(uint64_t projected, uint splat) {
    return UnpackProjectedSplat(
        ProjectedIn(RecordAddress(projected, splat, kProjectedSplatBytes)).words);
}

#endif  // OPEN3D_GAUSSIAN_DEVICE_ADDRESS_GLSL
