"""Does creating and destroying a Vulkan instance end this process's EGL displays?

Run on the GPU device machine (the loaders of .gl unpacked, __EGL_VENDOR_LIBRARY_FILENAMES set):
opens the GPU's EGL display two ways (the device platform, and Mesa's surfaceless platform
with EGL_EXT_explicit_device), creates and destroys a Vulkan instance, and prints whether each
display is still initialized; then the same with NVIDIA's Vulkan ICD pinned in memory
(RTLD_NODELETE), in case its unloading is what ends them. docs/environment-notes.md.
"""
import ctypes as C
import os
import sys

egl = C.CDLL("libEGL.so.1")
vk = C.CDLL("libvulkan.so.1")
egl.eglGetProcAddress.restype = C.c_void_p
egl.eglGetProcAddress.argtypes = [C.c_char_p]
egl.eglInitialize.argtypes = [C.c_void_p, C.c_void_p, C.c_void_p]
egl.eglQueryString.restype = C.c_char_p
egl.eglQueryString.argtypes = [C.c_void_p, C.c_int]
egl.eglGetPlatformDisplay.restype = C.c_void_p
egl.eglGetPlatformDisplay.argtypes = [C.c_uint, C.c_void_p, C.POINTER(C.c_ssize_t)]
query_devices = C.CFUNCTYPE(C.c_uint, C.c_int, C.POINTER(C.c_void_p), C.POINTER(C.c_int))(
    egl.eglGetProcAddress(b"eglQueryDevicesEXT"))
EGL_VENDOR, EGL_NONE = 0x3053, 0x3038
PLATFORM_DEVICE, PLATFORM_SURFACELESS, EGL_DEVICE = 0x313F, 0x31DD, 0x322C

devices = (C.c_void_p * 8)()
count = C.c_int()
query_devices(8, devices, C.byref(count))
displays = {
    "device platform": egl.eglGetPlatformDisplay(PLATFORM_DEVICE, devices[0], None),
    "surfaceless + explicit device": egl.eglGetPlatformDisplay(
        PLATFORM_SURFACELESS, None, (C.c_ssize_t * 3)(EGL_DEVICE, devices[0], EGL_NONE)),
}


def report(when):
    states = []
    for name, d in displays.items():
        alive = bool(d) and egl.eglQueryString(d, EGL_VENDOR) is not None
        states.append(f"{name} {'initialized' if alive else 'NOT initialized'}")
    print(f"{when}: " + "; ".join(states), flush=True)


class InstanceInfo(C.Structure):
    _fields_ = [("sType", C.c_uint), ("pNext", C.c_void_p), ("flags", C.c_uint),
                ("pApplicationInfo", C.c_void_p), ("enabledLayerCount", C.c_uint),
                ("ppEnabledLayerNames", C.c_void_p), ("enabledExtensionCount", C.c_uint),
                ("ppEnabledExtensionNames", C.c_void_p)]


def vulkan_instance_round_trip():
    info = InstanceInfo(1, None, 0, None, 0, None, 0, None)
    instance = C.c_void_p()
    result = vk.vkCreateInstance(C.byref(info), None, C.byref(instance))
    n = C.c_uint(0)
    vk.vkEnumeratePhysicalDevices(instance, C.byref(n), None)
    report(f"Vulkan instance made (result {result}, {n.value} devices)")
    vk.vkDestroyInstance(instance, None)


print(f"{count.value} EGL devices; displays {displays}", flush=True)
for d in displays.values():
    if d:
        egl.eglInitialize(d, None, None)
report("initialized")
vulkan_instance_round_trip()
report("Vulkan instance destroyed")
for d in displays.values():
    if d:
        egl.eglInitialize(d, None, None)
icd = sys.argv[1] if len(sys.argv) > 1 else "libGLX_nvidia.so.0"
C.CDLL(icd, mode=os.RTLD_NOW | getattr(os, "RTLD_NODELETE", 0x1000))
report(f"re-initialized, {icd} pinned")
vulkan_instance_round_trip()
report("Vulkan instance destroyed with the ICD pinned")
