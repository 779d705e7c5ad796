#include "vrdeform/render/gl_driver.h"

#include <dlfcn.h>
#include <link.h>

#include <string>
#include <string_view>
#include <vector>

namespace vrd {

void keepGlDriverLoaded() {
  std::vector<std::string> drivers;
  dl_iterate_phdr(
      [](dl_phdr_info* info, std::size_t, void* out) {
        const std::string_view name = info->dlpi_name ? info->dlpi_name : "";
        if (name.find("_dri.so") != std::string_view::npos || name.find("libGLX_mesa.so") != std::string_view::npos ||
            name.find("libEGL_mesa.so") != std::string_view::npos)
          static_cast<std::vector<std::string>*>(out)->emplace_back(name);
        return 0;
      },
      &drivers);
  // Outside the iteration, which holds the loader's lock: RTLD_NOLOAD | RTLD_NODELETE marks a
  // loaded library as never to be unloaded; the dlclose only returns this reference.
  for (const std::string& d : drivers)
    if (void* handle = dlopen(d.c_str(), RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE)) dlclose(handle);
}

}  // namespace vrd
