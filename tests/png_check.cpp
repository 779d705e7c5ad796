// vrdeform_png_check FILE: exits 0 when FILE is a PNG showing a body in its middle: within the
// central fifth of the image, at least a third of the pixels have the reddish colour of the
// liver scene's body (the ground is grey, the background blue-grey). The viewer's end-to-end test
// runs it on `vrdeform view liver --frames N --screenshot FILE`.

#include <cstdio>
#include <exception>

#include "vrdeform/render/image.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: vrdeform_png_check FILE.png\n");
    return 2;
  }
  try {
    const vrd::Image image = vrd::readPng(argv[1]);
    const int x0 = image.width * 2 / 5, x1 = image.width * 3 / 5, y0 = image.height * 2 / 5, y1 = image.height * 3 / 5;
    int body = 0, all = 0;
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x, ++all) {
        const auto p = image.pixel(x, y);
        body += p[0] > p[1] + 25 && p[0] > p[2] + 25;
      }
    std::printf("%s: %dx%d, %d of %d central pixels show the body\n", argv[1], image.width, image.height, body, all);
    return all > 0 && 3 * body >= all ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "vrdeform_png_check: %s\n", e.what());
    return 2;
  }
}
