"""An independent DDS peer of the chassis' ROS 2 node, on Cyclone DDS: the ROS message types
declared by hand (`msgs`), an independent CDR encoder to compare bytes with (`cdr`, on
`rosbags`), the participant that drives `/cmd_vel` and records what the node publishes
(`dds`), the processes under test (`procs`) and the private network namespace (`netns`)."""
