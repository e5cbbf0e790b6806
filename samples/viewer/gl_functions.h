// SPDX-License-Identifier: MIT
/* The OpenGL 3.3 core functions the viewer calls, loaded at run time through
 * glfwGetProcAddress (no GL loader library needed). X(return type, name, parameters). */
#define AGLOD_VIEWER_GL_FUNCTIONS(X)                                                              \
    X(const GLubyte*, glGetString, (GLenum name))                                                \
    X(GLenum, glGetError, (void))                                                                \
    X(void, glViewport, (GLint x, GLint y, GLsizei w, GLsizei h))                                \
    X(void, glClearColor, (GLfloat r, GLfloat g, GLfloat b, GLfloat a))                          \
    X(void, glClear, (GLbitfield mask))                                                          \
    X(void, glEnable, (GLenum cap))                                                              \
    X(void, glDisable, (GLenum cap))                                                             \
    X(void, glDepthFunc, (GLenum func))                                                          \
    X(void, glPixelStorei, (GLenum pname, GLint param))                                          \
    X(void, glReadBuffer, (GLenum mode))                                                         \
    X(void, glReadPixels, (GLint x, GLint y, GLsizei w, GLsizei h, GLenum format, GLenum type,   \
                           void* pixels))                                                        \
    X(void, glFinish, (void))                                                                    \
    X(void, glGenVertexArrays, (GLsizei n, GLuint* arrays))                                      \
    X(void, glBindVertexArray, (GLuint array))                                                   \
    X(void, glDeleteVertexArrays, (GLsizei n, const GLuint* arrays))                             \
    X(void, glGenBuffers, (GLsizei n, GLuint* buffers))                                          \
    X(void, glBindBuffer, (GLenum target, GLuint buffer))                                        \
    X(void, glBufferData, (GLenum target, GLsizeiptr size, const void* data, GLenum usage))      \
    X(void, glBufferSubData, (GLenum target, GLintptr offset, GLsizeiptr size, const void* data)) \
    X(void, glDeleteBuffers, (GLsizei n, const GLuint* buffers))                                 \
    X(void, glVertexAttribPointer, (GLuint index, GLint size, GLenum type, GLboolean normalized, \
                                    GLsizei stride, const void* pointer))                        \
    X(void, glEnableVertexAttribArray, (GLuint index))                                           \
    X(void, glDrawElements, (GLenum mode, GLsizei count, GLenum type, const void* indices))      \
    X(GLuint, glCreateShader, (GLenum type))                                                     \
    X(void, glShaderSource, (GLuint shader, GLsizei count, const GLchar* const* string,          \
                             const GLint* length))                                               \
    X(void, glCompileShader, (GLuint shader))                                                    \
    X(void, glGetShaderiv, (GLuint shader, GLenum pname, GLint* params))                         \
    X(void, glGetShaderInfoLog, (GLuint shader, GLsizei size, GLsizei* length, GLchar* log))     \
    X(void, glDeleteShader, (GLuint shader))                                                     \
    X(GLuint, glCreateProgram, (void))                                                           \
    X(void, glAttachShader, (GLuint program, GLuint shader))                                     \
    X(void, glBindAttribLocation, (GLuint program, GLuint index, const GLchar* name))            \
    X(void, glLinkProgram, (GLuint program))                                                     \
    X(void, glGetProgramiv, (GLuint program, GLenum pname, GLint* params))                       \
    X(void, glGetProgramInfoLog, (GLuint program, GLsizei size, GLsizei* length, GLchar* log))   \
    X(void, glUseProgram, (GLuint program))                                                      \
    X(void, glDeleteProgram, (GLuint program))                                                   \
    X(GLint, glGetUniformLocation, (GLuint program, const GLchar* name))                         \
    X(void, glUniformMatrix4fv, (GLint location, GLsizei count, GLboolean transpose,             \
                                 const GLfloat* value))                                          \
    X(void, glUniform3fv, (GLint location, GLsizei count, const GLfloat* value))                 \
    X(void, glUniform1i, (GLint location, GLint value))                                          \
    X(void, glGenFramebuffers, (GLsizei n, GLuint* framebuffers))                                \
    X(void, glBindFramebuffer, (GLenum target, GLuint framebuffer))                              \
    X(void, glDeleteFramebuffers, (GLsizei n, const GLuint* framebuffers))                       \
    X(GLenum, glCheckFramebufferStatus, (GLenum target))                                         \
    X(void, glGenRenderbuffers, (GLsizei n, GLuint* renderbuffers))                              \
    X(void, glBindRenderbuffer, (GLenum target, GLuint renderbuffer))                            \
    X(void, glDeleteRenderbuffers, (GLsizei n, const GLuint* renderbuffers))                     \
    X(void, glRenderbufferStorage, (GLenum target, GLenum format, GLsizei w, GLsizei h))         \
    X(void, glFramebufferRenderbuffer, (GLenum target, GLenum attachment, GLenum rbtarget,       \
                                        GLuint renderbuffer))                                    \
    X(void, glBlitFramebuffer, (GLint sx0, GLint sy0, GLint sx1, GLint sy1, GLint dx0, GLint dy0, \
                                GLint dx1, GLint dy1, GLbitfield mask, GLenum filter))           \
    X(void, glGenQueries, (GLsizei n, GLuint* ids))                                              \
    X(void, glDeleteQueries, (GLsizei n, const GLuint* ids))                                     \
    X(void, glBeginQuery, (GLenum target, GLuint id))                                            \
    X(void, glEndQuery, (GLenum target))                                                         \
    X(void, glGetQueryObjectuiv, (GLuint id, GLenum pname, GLuint* params))
