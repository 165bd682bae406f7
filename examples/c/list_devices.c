/* A C caller of planarvo: lists the OpenCL devices, creates a context on the default one (or
 * the one named by the first argument) and prints it. Build against an installed planarvo with
 *   cc list_devices.c $(pkg-config --cflags --libs planarvo)
 */
#include <planarvo/planarvo.h>
#include <stdio.h>
#include <stdlib.h>

int main(int argc, char** argv) {
  size_t count = 0;
  if (planarvo_list_devices(NULL, 0, &count) != PLANARVO_OK) {
    fprintf(stderr, "planarvo_list_devices: %s\n", planarvo_last_error());
    return 1;
  }
  planarvo_device_info* devices = calloc(count ? count : 1, sizeof *devices);
  for (size_t i = 0; i < count; ++i) devices[i].struct_size = sizeof *devices;
  if (planarvo_list_devices(devices, count, &count) != PLANARVO_OK) {
    fprintf(stderr, "planarvo_list_devices: %s\n", planarvo_last_error());
    free(devices);
    return 1;
  }
  for (size_t i = 0; i < count; ++i)
    printf("device %d: %s / %s (%s)\n", devices[i].index, devices[i].platform_name, devices[i].device_name,
           devices[i].device_type);
  free(devices);

  planarvo_context_options options;
  planarvo_context_options_init(&options);
  if (argc > 1) options.device = argv[1];
  planarvo_context* context = NULL;
  planarvo_status status = planarvo_context_create(&options, &context);
  if (status != PLANARVO_OK) {
    fprintf(stderr, "planarvo_context_create: %s: %s\n", planarvo_status_name(status), planarvo_last_error());
    return status == PLANARVO_ERROR_NO_DEVICE ? 3 : 1;
  }
  planarvo_device_info info;
  info.struct_size = sizeof info;
  planarvo_context_device(context, &info);
  printf("context on: %s (%s, %s)\n", info.device_name, info.device_version, info.opencl_c_version);
  planarvo_context_destroy(context);
  planarvo_context_destroy(NULL); /* destroy accepts NULL */
  return 0;
}
