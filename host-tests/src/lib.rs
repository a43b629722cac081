//! Host-side test support for `chassis-protocol`: stream generators shared by the integration
//! tests, the property tests and the fuzz targets.
