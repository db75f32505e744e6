# The libraries of the DICOM and TIFF readers (src/io/dicom.cpp, src/io/tiff.cpp), found for the
# build and again by cmc33Config.cmake for consumers of the installed static library.
#
# GDCM is found by its header and libraries rather than by its GDCMConfig.cmake: Debian's
# libgdcm-dev ships a config that names the command-line tools of another package and warns
# about each missing one.
#
# Sets CMC33_HAVE_GDCM / CMC33_HAVE_TIFF and the targets cmc33_gdcm and TIFF::TIFF.

set(CMC33_HAVE_GDCM OFF)
if(NOT DEFINED CMC33_WITH_GDCM OR CMC33_WITH_GDCM)
    find_path(CMC33_GDCM_INCLUDE_DIR gdcmReader.h PATH_SUFFIXES gdcm-3.0 gdcm-3.1 gdcm-3.2)
    find_library(CMC33_GDCM_MSFF gdcmMSFF)
    find_library(CMC33_GDCM_DSED gdcmDSED)
    find_library(CMC33_GDCM_COMMON gdcmCommon)
    find_library(CMC33_GDCM_DICT gdcmDICT) # the data dictionary: src/io/dicom.cpp judges VRs against it
    if(CMC33_GDCM_INCLUDE_DIR AND CMC33_GDCM_MSFF AND CMC33_GDCM_DSED AND CMC33_GDCM_COMMON AND CMC33_GDCM_DICT)
        set(CMC33_HAVE_GDCM ON)
        if(NOT TARGET cmc33_gdcm)
            add_library(cmc33_gdcm INTERFACE IMPORTED GLOBAL)
            set_target_properties(cmc33_gdcm PROPERTIES
                INTERFACE_INCLUDE_DIRECTORIES "${CMC33_GDCM_INCLUDE_DIR}"
                INTERFACE_LINK_LIBRARIES "${CMC33_GDCM_MSFF};${CMC33_GDCM_DICT};${CMC33_GDCM_DSED};${CMC33_GDCM_COMMON}")
        endif()
    endif()
endif()

set(CMC33_HAVE_TIFF OFF)
if(NOT DEFINED CMC33_WITH_TIFF OR CMC33_WITH_TIFF)
    find_package(TIFF QUIET)
    if(TIFF_FOUND)
        set(CMC33_HAVE_TIFF ON)
    endif()
endif()
