"""ROS bags: read posed frames (ROS 1 and ROS 2, sqlite3 or mcap), summarise, write.

The message shapes, PointCloud2 and raw Velodyne decoding, IMU samples and the choice of
topics a bag's frames come from.
"""

__all__: list[str] = []
