/* placeholder */
#include "serve_internal.h"
enum MHD_Result serve_outputs(serve_request *r)
{
    return serve_reply_error(r, 501, "not yet");
}
enum MHD_Result serve_cube(serve_request *r)
{
    return serve_reply_error(r, 501, "not yet");
}
enum MHD_Result serve_cube_data(serve_request *r)
{
    return serve_reply_error(r, 501, "not yet");
}
enum MHD_Result serve_pixel(serve_request *r)
{
    return serve_reply_error(r, 501, "not yet");
}
enum MHD_Result serve_diff(serve_request *r)
{
    return serve_reply_error(r, 501, "not yet");
}
void serve_cubes_free(serve *s)
{
    (void)s;
}
enum MHD_Result serve_photons(serve_request *r)
{
    return serve_reply_error(r, 501, "not yet");
}
enum MHD_Result serve_photons_info(serve_request *r)
{
    return serve_reply_error(r, 501, "not yet");
}
void serve_photons_free(serve *s)
{
    (void)s;
}
enum MHD_Result serve_validate(serve_request *r)
{
    return serve_reply_error(r, 501, "not yet");
}
enum MHD_Result serve_materials(serve_request *r)
{
    return serve_reply_error(r, 501, "not yet");
}
