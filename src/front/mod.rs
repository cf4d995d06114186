//! Front ends: Robotran C, Matlab and Python outputs → IR modules (parsed phase).
