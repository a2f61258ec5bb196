#ifndef CAMERA_EXPOSURE_GLSL
#define CAMERA_EXPOSURE_GLSL
// For the post nodes: camera.physical's exposure buffer (shaders/camera/exposure.h), bound at set 1 when the node's
// camera_state input is connected (the pipeline is then compiled with CAMERA_EXPOSURE; nodes/camera/camera_state.hpp's
// dispatchWithCamera binds it).
#ifdef CAMERA_EXPOSURE
#include "camera/exposure.h"
layout(std430, set = 1, binding = 0) readonly buffer CameraExposureBlock { CameraExposure cameraExposure; };
#endif
#endif
