# cmake -DIN=file -DOUT=file.inc -P embed_text.cmake: the file as one C++ raw string literal.
file(READ ${IN} text)
string(FIND "${text}" ")ICEFTEXT\"" clash)
if(NOT clash EQUAL -1)
  message(FATAL_ERROR "${IN} contains the raw-string delimiter )ICEFTEXT\"")
endif()
file(WRITE ${OUT} "R\"ICEFTEXT(${text})ICEFTEXT\"\n")
