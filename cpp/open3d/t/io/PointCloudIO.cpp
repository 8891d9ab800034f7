#include "open3d/t/io/PointCloudIO.h"
