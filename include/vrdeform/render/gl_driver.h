#pragma once
// The OpenGL driver's lifetime in the process.

namespace vrd {

/// Keeps the loaded OpenGL driver libraries (Mesa's *_dri.so, libGLX_mesa, libEGL_mesa) loaded
/// until the process ends, even after the last context and display close. Mesa keeps a few
/// driver-global allocations that it never frees; once the driver is unloaded, LeakSanitizer
/// reports them as leaks from an unknown module, which no suppression can name. Call it with a
/// context current (the driver is loaded then).
void keepGlDriverLoaded();

}  // namespace vrd
