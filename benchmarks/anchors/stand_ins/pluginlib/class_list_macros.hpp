// SPDX-License-Identifier: BSD-3-Clause
// Copyright (c) 2026 the kiseki authors
//
// Stand-in for ROS pluginlib's class_list_macros.hpp, which nav2_amcl's motion models include
// to register themselves as plugins. The harness makes its motion model directly, so the
// registration is not needed outside ROS: the macro expands to nothing.
#pragma once

#define PLUGINLIB_EXPORT_CLASS(class_type, base_class_type)
