#include "datasets/h5util.h"

int tcb_h5_shape_of(hid_t file, const char *name, tcb_h5_shape *out)
{
    if (H5Lexists(file, name, H5P_DEFAULT) <= 0) return -1;
    hid_t ds = H5Dopen2(file, name, H5P_DEFAULT);
    if (ds < 0) return -1;
    hid_t space = H5Dget_space(ds), type = H5Dget_type(ds);
    out->rank = space >= 0 ? H5Sget_simple_extent_ndims(space) : -1;
    out->type_class = type >= 0 ? H5Tget_class(type) : H5T_NO_CLASS;
    int ok = out->rank >= 0 && out->type_class != H5T_NO_CLASS &&
             H5Sget_simple_extent_dims(space, out->dims, NULL) == out->rank;
    if (type >= 0) H5Tclose(type);
    if (space >= 0) H5Sclose(space);
    H5Dclose(ds);
    return ok ? 0 : -1;
}
