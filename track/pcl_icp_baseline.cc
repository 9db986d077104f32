#include "track/internal/pcl_icp_baseline.h"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/icp.h>

#include <optional>

#include "track/proxy_model.h"
#include "track/segmentation.h"
#include "track/table_plane.h"

namespace mmh::track::internal {

struct PclIcpBaseline::Impl {
  PclIcpBaselineOptions options;
  TrackSetup setup;
  ProxyModel model;
  Segmenter segmenter;
  Segmentation segmentation;
  pcl::PointCloud<pcl::PointNormal>::Ptr target{new pcl::PointCloud<pcl::PointNormal>};
  pcl::IterativeClosestPointWithNormals<pcl::PointNormal, pcl::PointNormal> icp;
  Rigid3 last;
  std::optional<Rigid3> velocity;

  Impl(const TriangleMesh& mesh, const TrackSetup& s, const PclIcpBaselineOptions& o,
       const Rigid3& initial)
      : options(o),
        setup(s),
        model(mesh, ProxyModelOptions(), "model"),
        segmenter(SegmentationOptions(), s),
        last(initial) {
    for (size_t i = 0; i < model.points().size(); ++i) {
      pcl::PointNormal p;
      p.x = model.points()[i].x();
      p.y = model.points()[i].y();
      p.z = model.points()[i].z();
      p.normal_x = model.normals()[i].x();
      p.normal_y = model.normals()[i].y();
      p.normal_z = model.normals()[i].z();
      target->push_back(p);
    }
    icp.setInputTarget(target);
    icp.setMaximumIterations(options.max_iterations);
    icp.setMaxCorrespondenceDistance(options.max_correspondence_distance);
    icp.setTransformationEpsilon(1e-8);
  }
};

PclIcpBaseline::PclIcpBaseline(const TriangleMesh& model, const TrackSetup& setup,
                               const PclIcpBaselineOptions& options,
                               const Rigid3& initial_camera_T_proxy)
    : impl_(std::make_unique<Impl>(model, setup, options, initial_camera_T_proxy)) {}

PclIcpBaseline::~PclIcpBaseline() = default;

Rigid3 PclIcpBaseline::Track(const RgbdFrame& frame) {
  Impl& s = *impl_;
  if (!s.segmenter.has_table()) {
    std::string why;
    const auto plane = EstimateTablePlane(frame, TablePlaneOptions(), s.setup.camera_T_table, &why);
    if (!plane) return s.last;
    s.segmenter.SetTable(TableFrameOnPlane(*plane, s.setup.camera_T_table), frame.depth_intrinsics);
  }
  s.segmenter.Segment(frame, &s.segmentation);
  const Rigid3 predicted = s.velocity ? *s.velocity * s.last : s.last;
  if (s.segmentation.points.size() < 30) return predicted;
  pcl::PointCloud<pcl::PointNormal>::Ptr source(new pcl::PointCloud<pcl::PointNormal>);
  const size_t stride = std::max<size_t>(
      1, (s.segmentation.points.size() + s.options.max_points - 1) / s.options.max_points);
  for (size_t i = 0; i < s.segmentation.points.size(); i += stride) {
    pcl::PointNormal p;
    p.x = s.segmentation.points[i].x();
    p.y = s.segmentation.points[i].y();
    p.z = s.segmentation.points[i].z();
    p.normal_x = p.normal_y = p.normal_z = 0.0f;
    source->push_back(p);
  }
  s.icp.setInputSource(source);
  pcl::PointCloud<pcl::PointNormal> aligned;
  const Rigid3 guess = predicted.Inverse();  // proxy_T_camera
  Eigen::Matrix4f guess_matrix = Eigen::Matrix4f::Identity();
  guess_matrix.topLeftCorner<3, 3>() = guess.rotation.toRotationMatrix().cast<float>();
  guess_matrix.topRightCorner<3, 1>() = guess.translation.cast<float>();
  s.icp.align(aligned, guess_matrix);
  const Eigen::Matrix4d result = s.icp.getFinalTransformation().cast<double>();
  const Rigid3 proxy_T_camera(
      Eigen::Quaterniond(Eigen::Matrix3d(result.topLeftCorner<3, 3>())).normalized(),
      result.topRightCorner<3, 1>());
  const Rigid3 camera_T_proxy = proxy_T_camera.Inverse();
  s.velocity = camera_T_proxy * s.last.Inverse();
  s.last = camera_T_proxy;
  return camera_T_proxy;
}

}  // namespace mmh::track::internal
